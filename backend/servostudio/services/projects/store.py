"""The project store: one directory per project under a root directory.

Layout (docs/projects.md)::

    <root>/<project>/project.toml
    <root>/<project>/<axis>/DRIVEPAR.TXT, USER_PAR.TXT, SEQUENCE.TXT

Concurrency: operations on one project hold an exclusive ``flock`` on the project directory; operations that create,
rename or remove project directories also hold one on the root. A change names the revision the caller last saw
(``expected_revision``); if the project changed since, :class:`ConflictError` is raised and nothing is written.
The revision is a hash of the project's files, so it costs nothing in git and follows edits made outside the tool.

Crashes: every write is atomic (a temporary file renamed into place, a staging directory renamed into place), so a
process killed mid-save leaves the old or the new file and, at most, its temporary; `remove_stale_temporaries`
(at server start) removes those under the lock their writers hold.  Messages name projects, axes and files by
their place in the store, never by a server path.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import re
import shutil
import tempfile
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, fields, replace
from pathlib import Path
from typing import Any, Protocol

from servostudio.services.projects import layout
from servostudio.services.projects.devices import axis_files
from servostudio.services.projects.errors import (
    ConflictError,
    FileFormatError,
    ProjectExists,
    ProjectNotFound,
    ValidationError,
)
from servostudio.services.projects.fsutil import atomic_write, is_same_directory, locked_directory
from servostudio.services.projects.model import Axis, Bus, Project, from_text, to_text
from servostudio.services.projects.names import check_name, is_valid_name, same_name
from servostudio.services.projects.validation import validate_project

#: what interrupted writes leave: an atomic write's temporary file, a staging directory, a trash directory
_TEMPORARY = re.compile(r"\.(?:.+\.tmp|new-.+|deleted-.+)", re.DOTALL)
#: an archive is unpacked into a staging directory of the root without the store lock: one younger than this may
#: still be in use by another process
STAGING_GRACE = 60.0


class DeviceCatalog(Protocol):
    """What the store needs from the EDS library: the device keys it may reference."""

    def devices(self) -> list[str]: ...


class ProjectJournal(Protocol):
    """Who is told what each change wrote: the audit log (``services.audit.ProjectAudit``)."""

    def axis_file(self, project: str, axis: str, file_name: str, old: bytes, new: bytes) -> None: ...

    def project(self, project: str, what: str) -> None: ...


class _Unrecorded:
    """A store nobody audits (tools and tests that build one on its own)."""

    def axis_file(self, project: str, axis: str, file_name: str, old: bytes, new: bytes) -> None:
        return None

    def project(self, project: str, what: str) -> None:
        return None


UNRECORDED: ProjectJournal = _Unrecorded()


@dataclass(frozen=True)
class Snapshot:
    """A project as read under its lock, with the revision to pass back with the next change."""

    project: Project
    revision: str


class ProjectEdit:
    """A project opened for change inside :meth:`ProjectStore.edit`; writes go straight to disk, atomically."""

    def __init__(self, directory: Path, project: Project, journal: ProjectJournal = UNRECORDED) -> None:
        self.directory = directory
        self.project = project
        self.revision = ""
        self.journal = journal

    def axis(self, name: str) -> Axis:
        axis = self.project.axis(name)
        if axis is None:
            known = ", ".join(a.name for a in self.project.axes) or "none"
            raise ProjectNotFound(f"project '{self.project.name}' has no axis '{name}' (axes: {known})")
        return axis

    def axis_directory(self, name: str) -> Path:
        return self.directory / self.axis(name).name

    def write_axis_file(self, axis: str, file_name: str, data: bytes) -> None:
        directory = self.axis_directory(axis)
        directory.mkdir(exist_ok=True)
        path = directory / file_name
        old = path.read_bytes() if path.is_file() else b""
        atomic_write(path, data)
        self.journal.axis_file(self.project.name, axis, file_name, old, data)

    def save(self, project: Project) -> None:
        atomic_write(self.directory / layout.PROJECT_FILE, to_text(project))
        self.journal.project(self.project.name, f"project file saved ({_changes(self.project, project)})")
        self.project = project


def _changes(old: Project, new: Project) -> str:
    """Which fields of the project file a save changed, for the journal."""
    changed = [item.name for item in fields(Project) if getattr(old, item.name) != getattr(new, item.name)]
    return ", ".join(changed) or "unchanged"


class ProjectStore:
    def __init__(self, root: Path, devices: DeviceCatalog, journal: ProjectJournal = UNRECORDED) -> None:
        self.root = Path(root)
        self._devices = devices
        self.journal = journal

    # ---- projects -------------------------------------------------------------------------------------------

    def names(self) -> list[str]:
        if not self.root.is_dir():
            return []
        return sorted(
            (
                entry.name
                for entry in self.root.iterdir()
                if is_valid_name(entry.name) and (entry / layout.PROJECT_FILE).is_file()
            ),
            key=str.casefold,
        )

    def open(self, name: str) -> Snapshot:
        with self._project_lock(name, exclusive=False) as directory:
            return Snapshot(self._read(directory), revision_of(directory))

    def create(self, name: str, description: str = "", buses: tuple[Bus, ...] = ()) -> Snapshot:
        project = Project(check_name(name, "project"), description, buses)
        validate_project(project, self._devices.devices())
        self.root.mkdir(parents=True, exist_ok=True)
        with self._store_lock():
            self._refuse_existing(name)
            with self.staging() as staging:
                atomic_write(staging / layout.PROJECT_FILE, to_text(project))
                os.rename(staging, self.root / name)
            self.journal.project(name, "created")
            return Snapshot(project, revision_of(self.root / name))

    def update(
        self,
        name: str,
        expected_revision: str | None = None,
        *,
        description: str | None = None,
        buses: tuple[Bus, ...] | None = None,
    ) -> Snapshot:
        with self.edit(name, expected_revision) as edit:
            project = edit.project
            if description is not None:
                project = replace(project, description=description)
            if buses is not None:
                project = replace(project, buses=buses)
            self._validate(project)
            edit.save(project)
        return Snapshot(edit.project, edit.revision)

    def rename(self, name: str, new_name: str, expected_revision: str | None = None) -> Snapshot:
        check_name(new_name, "project")
        with self._store_lock(), self.edit(name, expected_revision) as edit:
            if not same_name(name, new_name):
                self._refuse_existing(new_name)
            edit.save(replace(edit.project, name=new_name))
            os.rename(self.root / name, self.root / new_name)
            edit.directory = self.root / new_name
        return Snapshot(edit.project, edit.revision)

    def duplicate(self, name: str, new_name: str) -> Snapshot:
        check_name(new_name, "project")
        with self._store_lock():
            self._refuse_existing(new_name)
            with self._project_lock(name, exclusive=False) as source, self.staging() as staging:
                shutil.rmtree(staging)
                shutil.copytree(source, staging, symlinks=True, ignore=_ignore_temporary)
                copy = replace(self._read(source), name=new_name)
                atomic_write(staging / layout.PROJECT_FILE, to_text(copy))
                os.rename(staging, self.root / new_name)
            self.journal.project(new_name, f"created as a copy of '{name}'")
            return Snapshot(copy, revision_of(self.root / new_name))

    def delete(self, name: str, expected_revision: str | None = None) -> None:
        with self._store_lock(), self.edit(name, expected_revision) as edit:
            trash = Path(tempfile.mkdtemp(dir=self.root, prefix=".deleted-"))
            os.rename(edit.directory, trash / name)
            edit.directory = trash / name
            self.journal.project(name, "deleted")
        shutil.rmtree(trash)

    # ---- axes -----------------------------------------------------------------------------------------------

    def add_axis(self, name: str, axis: Axis, expected_revision: str | None = None) -> Snapshot:
        return self.add_axes(name, (axis,), expected_revision)

    def add_axes(
        self, name: str, axes: tuple[Axis, ...], expected_revision: str | None = None, buses: tuple[Bus, ...] = ()
    ) -> Snapshot:
        """Add buses and axes in one change (a scan adds its findings together): all are validated first; an axis
        directory is built in a staging directory and renamed into place before the project file names it."""
        with self.edit(name, expected_revision) as edit:
            project = replace(edit.project, buses=(*edit.project.buses, *buses), axes=(*edit.project.axes, *axes))
            self._validate(project)
            for axis in axes:
                directory = edit.directory / axis.name
                if directory.exists():
                    raise ProjectExists(
                        f"'{name}/{axis.name}' already exists but is not an axis of project '{name}';"
                        " move it away or choose another axis name"
                    )
            for axis in axes:
                with self.staging(edit.directory) as staging:
                    for file_name in axis_files(axis.device):
                        atomic_write(staging / file_name, "")
                    os.rename(staging, edit.directory / axis.name)
            edit.save(project)
        return Snapshot(edit.project, edit.revision)

    def edit_axis(self, project: str, axis_name: str, expected_revision: str | None = None, **changes: Any) -> Snapshot:
        """Change fields of an axis (``name``, ``device``, ``node_id``, ``bus``, ``description``); renaming an axis
        renames its directory."""
        unknown = set(changes) - {"name", "device", "node_id", "bus", "description"}
        if unknown:
            raise ValidationError(f"cannot change axis field(s) {', '.join(sorted(unknown))} here")
        with self.edit(project, expected_revision) as edit:
            old = edit.axis(axis_name)
            new = replace(old, **changes)
            changed = edit.project.with_axes(tuple(new if axis is old else axis for axis in edit.project.axes))
            self._validate(changed)
            moving = new.name != old.name and (edit.directory / old.name).is_dir()
            if moving and (edit.directory / new.name).exists() and not same_name(old.name, new.name):
                raise ProjectExists(f"'{project}/{new.name}' already exists; choose another axis name")
            if new.device != old.device:
                _switch_device_files(edit.directory / old.name, old, new.device)
            if moving:
                os.rename(edit.directory / old.name, edit.directory / new.name)
            edit.save(changed)
        return Snapshot(edit.project, edit.revision)

    def replace_axis(self, edit: ProjectEdit, axis: Axis) -> None:
        """Store changed choices of an axis (motor, application) inside an edit the caller already holds."""
        project = edit.project.with_axes(tuple(axis if a.name == axis.name else a for a in edit.project.axes))
        self._validate(project)
        edit.save(project)

    def remove_axis(self, name: str, axis_name: str, expected_revision: str | None = None) -> Snapshot:
        with self.edit(name, expected_revision) as edit:
            removed = edit.axis(axis_name)
            edit.save(edit.project.with_axes(tuple(a for a in edit.project.axes if a is not removed)))
            if (edit.directory / removed.name).is_dir():
                trash = Path(tempfile.mkdtemp(dir=edit.directory, prefix=".deleted-"))
                os.rename(edit.directory / removed.name, trash / removed.name)
                shutil.rmtree(trash)
        return Snapshot(edit.project, edit.revision)

    # ---- building blocks for the other project services -------------------------------------------------------

    @contextlib.contextmanager
    def edit(self, name: str, expected_revision: str | None = None) -> Iterator[ProjectEdit]:
        """Lock the project, check the revision, hand out a :class:`ProjectEdit`; its ``revision`` is set on exit."""
        with self._project_lock(name, exclusive=True) as directory:
            if expected_revision is not None:
                actual = revision_of(directory)
                if actual != expected_revision:
                    raise ConflictError(name, expected_revision, actual)
            edit = ProjectEdit(directory, self._read(directory), self.journal)
            yield edit
            edit.revision = revision_of(edit.directory)

    @contextlib.contextmanager
    def read(self, name: str) -> Iterator[ProjectEdit]:
        """Hold a shared lock while reading several files of one project consistently."""
        with self._project_lock(name, exclusive=False) as directory:
            view = ProjectEdit(directory, self._read(directory))
            view.revision = revision_of(directory)
            yield view

    def project_directory(self, name: str) -> Path:
        check_name(name, "project")
        return self.root / name

    @contextlib.contextmanager
    def _store_lock(self) -> Iterator[None]:
        """Exclusive lock on the store directory, for operations that add, rename or remove project directories."""
        if not self.root.is_dir():
            raise ProjectNotFound("the project store does not exist")
        with locked_directory(self.root):
            yield

    @contextlib.contextmanager
    def _project_lock(self, name: str, exclusive: bool) -> Iterator[Path]:
        directory = self.project_directory(name)
        if not (directory / layout.PROJECT_FILE).is_file():
            raise ProjectNotFound(f"no project '{name}' in the project store")
        with locked_directory(directory, exclusive) as locked:
            if not is_same_directory(locked, directory):
                raise ProjectNotFound(f"project '{name}' was renamed or deleted meanwhile")
            with _named_in_project(directory):
                yield directory

    @contextlib.contextmanager
    def staging(self, parent: Path | None = None) -> Iterator[Path]:
        """A temporary directory next to the target: renaming it into place is the commit; on error it vanishes."""
        staging = Path(tempfile.mkdtemp(dir=parent or self.root, prefix=".new-"))
        staging.chmod(0o755)  # mkdtemp makes it private; a project directory is an ordinary directory
        try:
            yield staging
        finally:
            shutil.rmtree(staging, ignore_errors=True)

    def adopt(
        self, directory: Path, name: str, rename: bool, verify: Callable[[Path, Project], None] | None = None
    ) -> None:
        """Move a complete project directory (built in :meth:`staging`) into the store as ``name``.

        The project file is validated (and ``verify`` may check the axis files), and rewritten only when the
        project gets a new name, so an unpacked archive is byte-identical to the archived project.
        """
        check_name(name, "project")
        with self._store_lock():
            self._refuse_existing(name)
            project = replace(self._read(directory), name=name)
            self._validate(project)
            if verify is not None:
                verify(directory, project)
            if rename:
                atomic_write(directory / layout.PROJECT_FILE, to_text(project))
            os.rename(directory, self.root / name)
            self.journal.project(name, "imported from an archive")

    def remove_stale_temporaries(self) -> int:
        """Remove what interrupted saves left in the store (the server does at start) and say how many entries went.

        Each project is cleaned under its exclusive lock and the root under the store lock — the locks their writers
        hold — so a save in progress in another process is never touched."""
        if not self.root.is_dir():
            return 0
        with locked_directory(self.root):
            removed = _remove_temporaries(self.root, STAGING_GRACE, recurse=False)
        for name in self.names():
            with contextlib.suppress(ProjectNotFound), self._project_lock(name, exclusive=True) as directory:
                removed += _remove_temporaries(directory)
        return removed

    def _read(self, directory: Path) -> Project:
        path = directory / layout.PROJECT_FILE
        return from_text(path.read_text(encoding="utf-8"), path, directory.name)

    def _validate(self, project: Project) -> None:
        validate_project(project, self._devices.devices())

    def _refuse_existing(self, name: str) -> None:
        for existing in self.root.iterdir():
            if same_name(existing.name, name):
                raise ProjectExists(f"'{existing.name}' already exists in the project store; choose another name")


@contextlib.contextmanager
def _named_in_project(directory: Path) -> Iterator[None]:
    """A malformed file of the project is named by its place in the project (``demo/X/DRIVEPAR.TXT``), not by its
    server path: the message goes to browsers and scripts, which know the project, not the server's disk."""
    try:
        yield
    except FileFormatError as error:
        path = Path(error.file)
        if not path.is_relative_to(directory):
            raise
        place = Path(directory.name, path.relative_to(directory)).as_posix()
        raise FileFormatError(place, error.line, error.reason) from None


def _switch_device_files(directory: Path, axis: Axis, device: str) -> None:
    """Give an axis the empty files of another device. Values and sequences belong to one device's dictionary and
    do not carry over, so an axis whose files hold anything keeps its device."""
    directory.mkdir(exist_ok=True)
    files = [path for path in directory.iterdir() if path.is_file() and not path.name.startswith(layout.TEMP_PREFIX)]
    if any(path.stat().st_size for path in files):
        raise ValidationError(
            f"axis '{axis.name}' holds values for device '{axis.device}'; add a new axis for the other device instead"
        )
    wanted = axis_files(device)
    for path in files:
        if path.name not in wanted:
            path.unlink()
    for file_name in wanted:
        if not (directory / file_name).exists():
            atomic_write(directory / file_name, "")


def revision_of(directory: Path) -> str:
    """Hash of every file of the project (paths and contents): changes whenever anything in the project changes.

    Saved oscilloscope captures (``<axis>/captures/``) and procedure results (``<axis>/procedures/``) are records,
    not settings: saving one must not make another client's next parameter change a conflict, so they are left out
    (they are still archived)."""
    digest = hashlib.sha256()
    for path in setting_files(directory):
        relative = path.relative_to(directory).as_posix()
        digest.update(relative.encode() + b"\0" + path.read_bytes() + b"\0")
    return digest.hexdigest()[:16]


def setting_files(directory: Path) -> list[Path]:
    """The files that make a project's revision, sorted: every regular file but the records (captures, results)."""
    return sorted(
        path
        for path in _project_files(directory)
        if path.relative_to(directory).as_posix().split("/")[1:2] not in RECORD_DIRS
    )


#: second path components (``<axis>/<dir>/…``) whose files are records, not settings
RECORD_DIRS = ([layout.CAPTURES_DIR], [layout.PROCEDURES_DIR], [layout.FREQUENCY_DIR])


def _project_files(directory: Path) -> Iterator[Path]:
    """The regular files of a project; temporary entries and symbolic links are not part of it."""
    for current, dirs, files in os.walk(directory):
        dirs[:] = [d for d in dirs if not d.startswith(layout.TEMP_PREFIX)]
        for file_name in files:
            path = Path(current) / file_name
            if not file_name.startswith(layout.TEMP_PREFIX) and not path.is_symlink() and path.is_file():
                yield path


def _remove_temporaries(directory: Path, min_age: float = 0.0, recurse: bool = True) -> int:
    """Remove the temporaries directly in ``directory`` older than ``min_age`` s (and, with ``recurse``, those of its
    subdirectories: the axes)."""
    removed = 0
    for entry in list(directory.iterdir()):
        if entry.is_symlink():
            continue
        if _TEMPORARY.fullmatch(entry.name) and time.time() - entry.lstat().st_mtime >= min_age:
            _remove(entry)
            removed += 1
        elif recurse and entry.is_dir() and not entry.name.startswith(layout.TEMP_PREFIX):
            removed += _remove_temporaries(entry)
    return removed


def _remove(entry: Path) -> None:
    if entry.is_dir():
        shutil.rmtree(entry, ignore_errors=True)
    else:
        entry.unlink(missing_ok=True)


def _ignore_temporary(_directory: str, names: list[str]) -> list[str]:
    return [name for name in names if name.startswith(layout.TEMP_PREFIX)]
