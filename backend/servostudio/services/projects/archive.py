"""Archive / unarchive a project as one zip file (manual L411-431 names the commands, not the format).

The zip holds one top-level directory named after the project with the project's files below it, members sorted,
timestamps fixed, so archiving the same project twice gives the same bytes. Unpacking trusts nothing in the file:
every member name is checked as the archive spells it (no absolute path, no drive letter, no ``..``, no backslash,
no NUL anywhere — ``zipfile`` would silently cut the name at a NUL), links and special files are refused, and the
size of each member, of the total and the compression ratio are limited (zip bombs). The sizes checked are the
ones the zip declares; ``zipfile`` never inflates a member beyond its declared size and fails on a CRC mismatch,
so a zip lying about its sizes is refused as damaged. Everything is unpacked into a hidden staging
directory and renamed into place only when all members passed — and when the project file and every axis file
passed the editor's own rules (``verify``), ranges included — so a refused archive leaves no trace.  Messages name
the archive by its file name only, never by a server path.
"""

from __future__ import annotations

import os
import shutil
import stat
import zipfile
import zlib
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path, PurePosixPath

from servostudio.services.projects import layout
from servostudio.services.projects.errors import ArchiveError, FileFormatError
from servostudio.services.projects.model import Project
from servostudio.services.projects.names import check_name
from servostudio.services.projects.store import ProjectStore, Snapshot, _project_files

FIXED_TIME = (1980, 1, 1, 0, 0, 0)
_CHUNK = 64 * 1024


@dataclass(frozen=True)
class ArchiveLimits:
    """Defaults leave room for large sequence and parameter files while stopping runaway archives."""

    max_member_bytes: int = 16 * 1024 * 1024
    max_total_bytes: int = 64 * 1024 * 1024
    max_members: int = 10_000
    max_ratio: int = 200  # inflated / compressed bytes per member; text compresses ~5-20x


DEFAULT_LIMITS = ArchiveLimits()


def archive_project(store: ProjectStore, name: str, destination: Path) -> Path:
    """Write the project ``name`` into the zip ``destination`` (atomically) and return the path."""
    destination = Path(destination)
    with store.read(name) as view:
        temporary = destination.with_name(f".{destination.name}.tmp")
        try:
            with zipfile.ZipFile(temporary, "w", compression=zipfile.ZIP_DEFLATED) as archive:
                for path in sorted(_project_files(view.directory)):
                    relative = path.relative_to(view.directory).as_posix()
                    info = zipfile.ZipInfo(f"{name}/{relative}", date_time=FIXED_TIME)
                    info.compress_type = zipfile.ZIP_DEFLATED
                    info.external_attr = (stat.S_IFREG | 0o644) << 16
                    archive.writestr(info, path.read_bytes())
            os.replace(temporary, destination)
        finally:
            temporary.unlink(missing_ok=True)
    return destination


def unarchive_project(
    store: ProjectStore,
    source: Path,
    new_name: str | None = None,
    limits: ArchiveLimits = DEFAULT_LIMITS,
    verify: Callable[[Path, Project], None] | None = None,
) -> Snapshot:
    """Unpack a project archive into the store (as ``new_name`` if given) and return it opened.

    ``verify(directory, project)`` may check the unpacked axis files before the project is accepted.
    Raises :class:`ArchiveError` for anything unsafe or malformed (a malformed file is named as
    ``ARCHIVE: MEMBER:LINE: reason``) and :class:`ProjectExists` when the name is taken; in both cases the store is
    unchanged.
    """
    source = Path(source)
    label = source.name  # what messages call the archive: its name, not where the server keeps it
    try:
        archive = zipfile.ZipFile(source)
    except (zipfile.BadZipFile, OSError) as error:
        reason = error.strerror if isinstance(error, OSError) else error
        raise ArchiveError(f"{label}: not a readable zip archive ({reason})") from None
    with archive:
        top = _check_members(archive, label, limits)
        name = check_name(new_name or top, "project")
        store.root.mkdir(parents=True, exist_ok=True)
        with store.staging() as staging:
            _extract(archive, label, staging)
            if not (staging / layout.PROJECT_FILE).is_file():
                raise ArchiveError(f"{label}: no {top}/{layout.PROJECT_FILE} in the archive; not a project archive")
            try:
                store.adopt(staging, name, rename=name != top, verify=verify)
            except FileFormatError as error:
                member = f"{top}/{Path(error.file).relative_to(staging).as_posix()}"
                raise ArchiveError(f"{label}: {member}:{error.line}: {error.reason}") from None
    return store.open(name)


def _check_members(archive: zipfile.ZipFile, source: str, limits: ArchiveLimits) -> str:
    """Validate every member name and type; return the single top-level directory name."""
    members = archive.infolist()
    if not members:
        raise ArchiveError(f"{source}: the archive is empty")
    if len(members) > limits.max_members:
        raise ArchiveError(f"{source}: {len(members)} members, more than the limit of {limits.max_members}")
    tops = set()
    for info in members:
        parts = _safe_parts(info, source)
        kind = stat.S_IFMT(info.external_attr >> 16)
        if kind == stat.S_IFLNK:
            raise ArchiveError(f"{source}: member '{info.filename}' is a symbolic link; links are not allowed")
        if kind not in (0, stat.S_IFREG, stat.S_IFDIR):
            raise ArchiveError(f"{source}: member '{info.filename}' is not a regular file or directory")
        if info.flag_bits & 0x1:
            raise ArchiveError(f"{source}: member '{info.filename}' is encrypted")
        if info.file_size > limits.max_member_bytes:
            raise ArchiveError(
                f"{source}: member '{info.filename}' is {info.file_size} bytes, more than the limit "
                f"of {limits.max_member_bytes}"
            )
        if info.file_size > limits.max_ratio * info.compress_size + _CHUNK:
            raise ArchiveError(
                f"{source}: member '{info.filename}' inflates {info.compress_size} to "
                f"{info.file_size} bytes; refusing a zip bomb"
            )
        tops.add(parts[0])
    declared = sum(info.file_size for info in members)
    if declared > limits.max_total_bytes:
        raise ArchiveError(
            f"{source}: the members add up to {declared} bytes, more than the limit of "
            f"{limits.max_total_bytes}; refusing a zip bomb"
        )
    if len(tops) != 1:
        raise ArchiveError(f"{source}: expected one top-level project directory, found {', '.join(sorted(tops))}")
    return tops.pop()


def _safe_parts(info: zipfile.ZipInfo, source: str) -> tuple[str, ...]:
    """The parts of a member's path; ``orig_filename`` is the name as stored (``filename`` is cut at a NUL)."""
    member = info.filename
    if "\0" in info.orig_filename:
        raise ArchiveError(f"{source}: member {info.orig_filename!r} contains a NUL in its name")
    if "\\" in member:
        raise ArchiveError(f"{source}: member '{member}' contains a backslash in its name")
    path = PurePosixPath(member)
    if path.is_absolute() or (path.parts and ":" in path.parts[0]):
        raise ArchiveError(f"{source}: member '{member}' has an absolute path")
    parts = tuple(part for part in path.parts if part != ".")
    if ".." in parts:
        raise ArchiveError(f"{source}: member '{member}' contains '..' (path traversal)")
    if not parts:
        raise ArchiveError(f"{source}: member '{member}' has an empty name")
    return parts


def _extract(archive: zipfile.ZipFile, source: str, staging: Path) -> None:
    """Copy the members; ``zipfile`` stops inflating at the declared size and fails on a CRC mismatch, so the
    checked sizes are the real ones."""
    for info in archive.infolist():
        parts = _safe_parts(info, source)[1:]
        target = staging.joinpath(*parts) if parts else staging
        if info.is_dir():
            target.mkdir(parents=True, exist_ok=True)
            continue
        if not parts:
            raise ArchiveError(f"{source}: member '{info.filename}' is a file where the project directory belongs")
        target.parent.mkdir(parents=True, exist_ok=True)
        try:
            with archive.open(info) as reader, open(target, "xb") as writer:
                shutil.copyfileobj(reader, writer, _CHUNK)
        except FileExistsError:
            raise ArchiveError(f"{source}: member '{info.filename}' appears twice") from None
        except (zipfile.BadZipFile, zipfile.LargeZipFile, zlib.error, EOFError, NotImplementedError) as error:
            raise ArchiveError(f"{source}: member '{info.filename}' is damaged ({error})") from None
