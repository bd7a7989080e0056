"""Archive / unarchive: identical round trip, and refusal of every unsafe archive without leaving anything behind."""

from __future__ import annotations

import stat
import zipfile
from pathlib import Path

import pytest

from servostudio.services.projects import ArchiveError, ArchiveLimits, Axis, ProjectExists, ProjectService


def _tree(root: Path) -> dict[str, bytes]:
    return {path.relative_to(root).as_posix(): path.read_bytes() for path in sorted(root.rglob("*")) if path.is_file()}


@pytest.fixture
def filled(sim_project: ProjectService) -> ProjectService:
    sim_project.store.add_axis("p", Axis("X", "xtrapulspac", 1, "sim"))
    sim_project.store.add_axis("p", Axis("Y", "xtrapulspac", 2, "sim"))
    sim_project.parameters.set("p", "X", {"0x6060": -3, "0x3051": 5})
    (sim_project.store.root / "p" / "Y" / "SEQUENCE.TXT").write_bytes(b"; sequences \xe9\r\n")
    return sim_project


def test_archive_then_unarchive_gives_an_identical_tree(filled: ProjectService, tmp_path: Path):
    archive = filled.archive("p", tmp_path / "p.zip")
    original = _tree(filled.store.root / "p")
    filled.store.delete("p")
    snapshot = filled.unarchive(archive)
    assert snapshot.project.name == "p"
    assert _tree(filled.store.root / "p") == original


def test_links_inside_a_project_are_not_archived(filled: ProjectService, tmp_path: Path):
    secret = tmp_path / "secret.txt"
    secret.write_text("not part of the project")
    (filled.store.root / "p" / "X" / "notes.txt").symlink_to(secret)
    archive = filled.archive("p", tmp_path / "p.zip")
    with zipfile.ZipFile(archive) as reader:
        assert "p/X/notes.txt" not in reader.namelist()
        assert "p/X/DRIVEPAR.TXT" in reader.namelist()


def test_archiving_twice_gives_the_same_bytes(filled: ProjectService, tmp_path: Path):
    assert filled.archive("p", tmp_path / "a.zip").read_bytes() == filled.archive("p", tmp_path / "b.zip").read_bytes()


def test_unarchive_under_a_new_name_keeps_the_original(filled: ProjectService, tmp_path: Path):
    archive = filled.archive("p", tmp_path / "p.zip")
    with pytest.raises(ProjectExists):
        filled.unarchive(archive)
    copy = filled.unarchive(archive, "p-restored")
    assert copy.project.name == "p-restored"
    assert [a.name for a in copy.project.axes] == ["X", "Y"]
    assert filled.store.names() == ["p", "p-restored"]


def _zip(path: Path, members: list[tuple[zipfile.ZipInfo | str, bytes]]) -> Path:
    with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_DEFLATED) as archive:
        for info, data in members:
            archive.writestr(info, data)
    return path


def _project_file() -> bytes:
    return b'[project]\nformat = 1\nname = "evil"\n'


def _link(name: str, target: str) -> zipfile.ZipInfo:
    info = zipfile.ZipInfo(name)
    info.external_attr = (stat.S_IFLNK | 0o777) << 16
    return info


@pytest.mark.parametrize(
    ("members", "message"),
    [
        ([("/etc/evil/project.toml", _project_file())], "absolute path"),
        ([("evil/project.toml", _project_file()), ("evil/../../outside.txt", b"x")], "path traversal"),
        ([("evil/project.toml", _project_file()), ("evil\\..\\x.txt", b"x")], "backslash"),
        ([("C:/evil/project.toml", _project_file())], "absolute path"),
        ([("evil/project.toml", _project_file()), (_link("evil/X", "/etc"), b"/etc")], "symbolic link"),
        ([("evil/project.toml", _project_file()), ("other/project.toml", _project_file())], "one top-level"),
        ([("evil/readme.txt", b"no project file")], "not a project archive"),
        ([], "empty"),
    ],
)
def test_unsafe_or_foreign_archives_are_refused(service: ProjectService, tmp_path: Path, members, message):
    archive = _zip(tmp_path / "evil.zip", members)
    with pytest.raises(ArchiveError, match=message):
        service.unarchive(archive)
    _assert_untouched(service, tmp_path)


def _assert_untouched(service: ProjectService, tmp_path: Path) -> None:
    assert not service.store.root.exists() or list(service.store.root.iterdir()) == []
    assert not (tmp_path / "outside.txt").exists()


def test_oversized_member_is_refused(service: ProjectService, tmp_path: Path):
    archive = _zip(tmp_path / "big.zip", [("evil/project.toml", _project_file()), ("evil/X/DRIVEPAR.TXT", b"0" * 5000)])
    with pytest.raises(ArchiveError, match="more than the limit of 4096"):
        service.unarchive(archive, limits=ArchiveLimits(max_member_bytes=4096))
    _assert_untouched(service, tmp_path)


def test_zip_bomb_is_refused_by_its_compression_ratio(service: ProjectService, tmp_path: Path):
    """10 MB of zeros deflate to ~10 kB: within the size limits, but no project file compresses 1000:1."""
    archive = _zip(
        tmp_path / "bomb.zip", [("evil/project.toml", _project_file()), ("evil/X/DRIVEPAR.TXT", b"\0" * 10_000_000)]
    )
    with pytest.raises(ArchiveError, match="zip bomb"):
        service.unarchive(archive)
    _assert_untouched(service, tmp_path)


def test_member_lying_about_its_size_is_refused(service: ProjectService, tmp_path: Path):
    """A header claiming 10 bytes for 1 MB of data: reading stops at the claimed size and the CRC gives it away."""
    archive = _zip(
        tmp_path / "liar.zip", [("evil/project.toml", _project_file()), ("evil/X/DRIVEPAR.TXT", b"\0" * 1_000_000)]
    )
    data = bytearray(archive.read_bytes())
    with zipfile.ZipFile(archive) as reader:
        info = reader.getinfo("evil/X/DRIVEPAR.TXT")
    for offset in (info.header_offset + 22, _central_offset(data, b"evil/X/DRIVEPAR.TXT") + 24):
        data[offset : offset + 4] = (10).to_bytes(4, "little")  # uncompressed size field
    archive.write_bytes(bytes(data))
    with pytest.raises(ArchiveError, match="damaged"):
        service.unarchive(archive)
    _assert_untouched(service, tmp_path)


def test_many_members_beyond_the_total_limit_are_refused(service: ProjectService, tmp_path: Path):
    members = [("evil/project.toml", _project_file())] + [
        (f"evil/X/file{number}.txt", bytes(range(256)) * 20) for number in range(20)
    ]
    archive = _zip(tmp_path / "many.zip", members)
    with pytest.raises(ArchiveError, match="add up to 102435 bytes"):
        service.unarchive(archive, limits=ArchiveLimits(max_total_bytes=50_000))
    _assert_untouched(service, tmp_path)


def test_not_a_zip_is_refused(service: ProjectService, tmp_path: Path):
    path = tmp_path / "junk.zip"
    path.write_bytes(b"this is not a zip archive")
    with pytest.raises(ArchiveError, match="not a readable zip"):
        service.unarchive(path)


def _central_offset(data: bytearray, name: bytes) -> int:
    """Offset of the central-directory record of ``name`` (signature PK\\x01\\x02)."""
    position = data.rfind(b"PK\x01\x02")
    while position != -1:
        if data[position + 46 : position + 46 + len(name)] == name:
            return position
        position = data.rfind(b"PK\x01\x02", 0, position)
    raise AssertionError("central directory record not found")


def _project_with_axis_files(drivepar: bytes, sequence: bytes) -> list[tuple[str, bytes]]:
    project = (
        b'[project]\nformat = 1\nname = "bad"\n\n[bus.sim]\ninterface = "sim"\n\n'
        b'[axis.X]\ndevice = "xtrapulspac"\nnode_id = 1\nbus = "sim"\n'
    )
    return [
        ("bad/project.toml", project),
        ("bad/X/DRIVEPAR.TXT", drivepar),
        ("bad/X/SEQUENCE.TXT", sequence),
        ("bad/X/USER_PAR.TXT", b""),
    ]


@pytest.mark.parametrize(
    ("drivepar", "sequence", "message"),
    [
        (b"0x3051,0=1\n0x2004,0=12\n", b"", r"bad/X/DRIVEPAR.TXT:2: 0x2004,0 .* expected text"),
        (b"0x3051,0=1\n0x304F,0=4194177\n", b"", r"bad/X/DRIVEPAR.TXT:2: 0x304F,0 .*4194176"),  # out of range
        (b"0x1000,0=1\n", b"", r"bad/X/DRIVEPAR.TXT:1: 0x1000,0 .*read-only"),  # the editor cannot write it
        (b"0x3051,0=1\n0x3051,0=2\n", b"", r"bad/X/DRIVEPAR.TXT:2: duplicate assignment"),
        (b"", b"; sequences\ngarbage\n", r"bad/X/SEQUENCE.TXT:2: expected 'Key_word = value'"),
    ],
)
def test_archives_with_broken_axis_files_are_refused(
    service: ProjectService, tmp_path: Path, drivepar: bytes, sequence: bytes, message: str
):
    archive = _zip(tmp_path / "bad.zip", _project_with_axis_files(drivepar, sequence))
    with pytest.raises(ArchiveError, match=message):
        service.unarchive(archive)
    _assert_untouched(service, tmp_path)


def test_archive_with_valid_axis_files_is_accepted(service: ProjectService, tmp_path: Path):
    archive = _zip(tmp_path / "good.zip", _project_with_axis_files(b"0x3051,0=1\n", b"SeqNb=1\nSeqType=POS\n"))
    snapshot = service.unarchive(archive)
    assert [axis.name for axis in snapshot.project.axes] == ["X"]
    assert service.parameters.get("bad", "X", "0x3051")[0].value == 1


def _with_nul_in_a_name(path: Path) -> Path:
    """An archive whose member ``bad/X/DRIVEPAR.TXT`` is stored as ``bad/X/DRIVE\\0AR.TXT`` (``zipfile`` itself
    writes no NUL; it reads the name cut at the NUL, which would make it a different file)."""
    _zip(path, _project_with_axis_files(b"0x3051,0=1\n", b""))
    data = path.read_bytes().replace(b"bad/X/DRIVEPAR.TXT", b"bad/X/DRIVE\0AR.TXT")
    path.write_bytes(data)
    return path


def test_a_nul_anywhere_in_a_member_name_is_refused(service: ProjectService, tmp_path: Path):
    with pytest.raises(ArchiveError, match=r"contains a NUL in its name"):
        service.unarchive(_with_nul_in_a_name(tmp_path / "nul.zip"))
    _assert_untouched(service, tmp_path)


def test_refusals_name_the_archive_by_its_name_only(service: ProjectService, tmp_path: Path):
    deep = tmp_path / "server" / "spool"
    deep.mkdir(parents=True)
    archive = _zip(deep / "upload.zip", _project_with_axis_files(b"0x304F,0=4194177\n", b""))
    with pytest.raises(ArchiveError) as refused:
        service.unarchive(archive)
    assert str(refused.value).startswith("upload.zip: bad/X/DRIVEPAR.TXT:1:")
    assert str(tmp_path) not in str(refused.value)
