"""The EDS library: built-in and user directories, validated atomic import, identity matching."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from servostudio.od import BUILTIN_EDS_DIR, DictionaryError, EdsLibrary, LibraryError, builtin_library

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture
def dirs(tmp_path: Path) -> tuple[Path, Path, Path]:
    builtin, user, incoming = tmp_path / "builtin", tmp_path / "user", tmp_path / "incoming"
    builtin.mkdir()
    incoming.mkdir()
    return builtin, user, incoming


def write_pair(directory: Path, name: str, eds: str, props: str | None) -> Path:
    (directory / f"{name}.eds").write_text(eds, encoding="utf-8")
    if props is not None:
        (directory / f"{name}.props").write_text(props, encoding="utf-8")
    return directory / f"{name}.eds"


def test_import_copies_a_valid_pair_and_the_library_serves_it(dirs, mini_eds: str, mini_props: str) -> None:
    builtin, user, incoming = dirs
    library = EdsLibrary(builtin, user)
    source = write_pair(incoming, "Acme_Drive", mini_eds, mini_props)
    key = library.import_eds(source)
    assert key == "acme_drive"
    assert sorted(p.name for p in user.iterdir()) == ["acme_drive.eds", "acme_drive.props"]
    assert (user / "acme_drive.eds").read_text() == mini_eds
    assert library.devices() == ["acme_drive"]
    od = library.load("acme_drive")
    assert od.device == "acme_drive" and od[0x2100, 0].unit == "rpm"
    assert library.load("acme_drive") is od, "dictionaries are cached"
    assert library.match(0x12, 0x34) == "acme_drive"
    assert library.match(0x12, 0x35) is None


def test_bad_eds_is_refused_and_nothing_is_copied(dirs, mini_eds: str, mini_props: str) -> None:
    builtin, user, incoming = dirs
    library = EdsLibrary(builtin, user)
    source = write_pair(incoming, "broken", mini_eds.replace("LowLimit=10", "LowLimit=-10"), mini_props)
    with pytest.raises(DictionaryError, match=r"broken\.eds:\d+: \[2100\]"):
        library.import_eds(source)
    assert not user.exists() or list(user.iterdir()) == []
    assert library.devices() == []


def test_bad_props_is_refused_and_nothing_is_copied(dirs, mini_eds: str, mini_props: str) -> None:
    builtin, user, incoming = dirs
    user.mkdir()
    library = EdsLibrary(builtin, user)
    source = write_pair(incoming, "acme", mini_eds, mini_props.replace("SaveType=USER_PAR", "SaveType=FLASH"))
    with pytest.raises(DictionaryError, match=r"acme\.props:\d+: \[2100\] SaveType"):
        library.import_eds(source)
    assert list(user.iterdir()) == []


def test_reimport_without_props_drops_the_stale_props(dirs, mini_eds: str, mini_props: str) -> None:
    builtin, user, incoming = dirs
    library = EdsLibrary(builtin, user)
    library.import_eds(write_pair(incoming, "acme", mini_eds, mini_props))
    assert library.load("acme")[0x2100, 0].unit == "rpm"
    (incoming / "acme.props").unlink()
    library.import_eds(incoming / "acme.eds")
    assert sorted(p.name for p in user.iterdir()) == ["acme.eds"]
    assert library.load("acme")[0x2100, 0].unit == "", "the cache was refreshed"


def test_builtin_keys_cannot_be_shadowed(dirs, mini_eds: str) -> None:
    builtin, user, incoming = dirs
    write_pair(builtin, "mini", mini_eds, None)
    library = EdsLibrary(builtin, user)
    with pytest.raises(LibraryError, match="built-in"):
        library.import_eds(write_pair(incoming, "MINI", mini_eds, None))
    assert not user.exists()
    assert library.devices() == ["mini"] and library.match(0x12, 0x34) == "mini"


def test_user_dictionaries_match_before_builtin_ones(dirs, mini_eds: str) -> None:
    builtin, user, incoming = dirs
    write_pair(builtin, "factory", mini_eds, None)
    library = EdsLibrary(builtin, user)
    library.import_eds(write_pair(incoming, "custom", mini_eds, None))
    assert library.devices() == ["custom", "factory"]
    assert library.match(0x12, 0x34) == "custom"


def test_errors_for_unknown_devices_and_missing_user_dir(dirs, mini_eds: str) -> None:
    builtin, _, incoming = dirs
    library = EdsLibrary(builtin)
    with pytest.raises(LibraryError, match="unknown device 'nope'"):
        library.load("nope")
    with pytest.raises(LibraryError, match="no user directory"):
        library.import_eds(write_pair(incoming, "acme", mini_eds, None))
    with pytest.raises(LibraryError, match="file name"):
        EdsLibrary(builtin, incoming / "lib").import_eds(write_pair(incoming, "bad name", mini_eds, None))


def test_builtin_library_is_the_repository_eds_folder() -> None:
    assert BUILTIN_EDS_DIR == REPO / "eds"
    library = builtin_library()
    assert library is builtin_library()
    assert {"xtrapulspac", "cd1k", "encotrive"} <= set(library.devices())
    assert library.match(0x82, library.load("xtrapulspac").product_code) == "xtrapulspac"


def test_environment_overrides_the_builtin_folder(dirs, mini_eds: str) -> None:
    builtin, _, _ = dirs
    write_pair(builtin, "only", mini_eds, None)
    code = "from servostudio.od import builtin_library; print(builtin_library().devices())"
    env = {**os.environ, "SERVOSTUDIO_EDS_DIR": str(builtin), "SERVOSTUDIO_USER_EDS_DIR": str(builtin / "none")}
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=60)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "['only']"
