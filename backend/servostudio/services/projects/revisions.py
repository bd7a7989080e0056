"""Kept revisions of a project: what a change that replaces many values (a backup of a drive into the project)
overwrote stays restorable.

A change asks for it (:func:`keeping`); the project's files as they were before it are copied to
``<project>/.revisions/<seq>-<revision>/`` (a dot entry: never part of the revision hash, archives or copies),
with ``about.json`` saying when, why and by whom. The newest :data:`KEEP` are kept. Restoring one (:func:`restore`)
is itself a change that keeps the state it replaces, so it can be undone the same way. Saved oscilloscope captures are
recordings, not settings: they are neither kept nor touched by a restore (as the revision hash leaves them out).
"""

from __future__ import annotations

import contextlib
import json
import shutil
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

from servostudio.services.audit import current_actor
from servostudio.services.projects import layout
from servostudio.services.projects.errors import ProjectNotFound
from servostudio.services.projects.fsutil import atomic_write
from servostudio.services.projects.model import Project, from_text
from servostudio.services.projects.store import ProjectEdit, revision_of, setting_files

REVISIONS_DIR = ".revisions"
ABOUT = "about.json"
#: how many kept revisions a project holds (the oldest goes first)
KEEP = 10


@dataclass(frozen=True)
class KeptRevision:
    revision: str
    saved_at: float  # epoch seconds: when the change that replaced it was made
    reason: str  # what replaced it ("backup of node 1 into the project", "restore of revision …")
    files: int
    by: str = ""  # who made that change (the audit log's user; "" in revisions kept before it was recorded)


def kept(directory: Path) -> list[KeptRevision]:
    """The kept revisions of the project in ``directory``, newest first."""
    return [_about(path) for path in _snapshots(directory)[::-1]]


@contextlib.contextmanager
def keeping(edit: ProjectEdit, reason: str) -> Iterator[None]:
    """Keep the project as it is now when the change made inside the block changes it; a failed or empty change
    keeps nothing."""
    before = revision_of(edit.directory)
    snapshot = _copy(edit.directory, before, reason)
    try:
        yield
    except BaseException:
        shutil.rmtree(snapshot, ignore_errors=True)
        raise
    if revision_of(edit.directory) == before:
        shutil.rmtree(snapshot, ignore_errors=True)
    else:
        _prune(edit.directory)


def restore(edit: ProjectEdit, revision: str, validate: Callable[[Project], None]) -> None:
    """Make the project's setting files those of the kept ``revision`` (inside an edit that holds the lock); its
    project file is read and ``validate``d (the store's rules) before anything is written."""
    snapshot = _find(edit.directory, revision)
    wanted = {path.relative_to(snapshot).as_posix(): path.read_bytes() for path in setting_files(snapshot)}
    wanted.pop(ABOUT, None)
    project_text = wanted.pop(layout.PROJECT_FILE)
    project = from_text(project_text.decode("utf-8"), edit.directory / layout.PROJECT_FILE, edit.project.name)
    validate(project)
    current = {path.relative_to(edit.directory).as_posix(): path for path in setting_files(edit.directory)}
    current.pop(layout.PROJECT_FILE, None)
    for relative, data in wanted.items():
        old = current[relative].read_bytes() if relative in current else b""
        if relative not in current or old != data:
            (edit.directory / relative).parent.mkdir(parents=True, exist_ok=True)
            atomic_write(edit.directory / relative, data)
            _journal(edit, relative, old, data)
    for relative in sorted(set(current) - set(wanted)):
        old = current[relative].read_bytes()
        current[relative].unlink()
        _journal(edit, relative, old, b"")
        _remove_if_empty(current[relative].parent, edit.directory)
    atomic_write(edit.directory / layout.PROJECT_FILE, project_text)
    edit.project = project
    edit.journal.project(edit.project.name, f"revision {revision} restored")


def _journal(edit: ProjectEdit, relative: str, old: bytes, new: bytes) -> None:
    axis, _, file_name = relative.partition("/")
    edit.journal.axis_file(edit.project.name, axis, file_name, old, new)


def _remove_if_empty(directory: Path, root: Path) -> None:
    """An axis directory the restored revision has no file in goes too (a later axis of that name starts empty)."""
    with contextlib.suppress(OSError):
        while directory != root and not any(directory.iterdir()):
            directory.rmdir()
            directory = directory.parent


def _copy(directory: Path, revision: str, reason: str) -> Path:
    root = directory / REVISIONS_DIR
    root.mkdir(exist_ok=True)
    numbers = [int(path.name[:6]) for path in root.iterdir() if path.name[:6].isdigit()]  # unfinished ones too
    snapshot = root / f"{max(numbers, default=0) + 1:06d}-{revision}"
    snapshot.mkdir()
    count = 0
    for path in setting_files(directory):
        target = snapshot / path.relative_to(directory)
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(path, target)
        count += 1
    about = {
        "revision": revision,
        "saved_at": time.time(),
        "reason": reason,
        "files": count,
        "by": current_actor().user,
    }
    atomic_write(snapshot / ABOUT, json.dumps(about))
    return snapshot


def _prune(directory: Path) -> None:
    for path in _snapshots(directory)[:-KEEP]:
        shutil.rmtree(path, ignore_errors=True)


def _snapshots(directory: Path) -> list[Path]:
    """The kept revisions' directories, oldest first (a directory without its about.json is unfinished)."""
    root = directory / REVISIONS_DIR
    if not root.is_dir():
        return []
    found = [path for path in root.iterdir() if path.is_dir() and (path / ABOUT).is_file()]
    return sorted(found, key=lambda path: path.name)


def _about(path: Path) -> KeptRevision:
    about = json.loads((path / ABOUT).read_text(encoding="utf-8"))
    fields = (str(about["revision"]), float(about["saved_at"]), str(about["reason"]), int(about["files"]))
    return KeptRevision(*fields, by=str(about.get("by", "")))


def _find(directory: Path, revision: str) -> Path:
    for path in _snapshots(directory)[::-1]:
        if _about(path).revision == revision:
            return path
    known = ", ".join(item.revision for item in kept(directory)) or "none"
    raise ProjectNotFound(f"project '{directory.name}' keeps no revision '{revision}' (kept: {known})")
