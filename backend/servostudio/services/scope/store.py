"""Captures saved in a project, under their axis: ``<project>/<axis>/captures/NAME.csv`` + ``NAME.json``.

Each file is written atomically (``fsutil.atomic_write``: a temporary file renamed into place) under the project's
lock, the CSV first and the sidecar last: a capture exists once its sidecar does, so a save interrupted between the
two leaves no capture that lists (the orphan CSV is overwritten by the next save of that name). Saved captures are
not part of the project's revision (``projects.store.revision_of``).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

from servostudio.errors import Conflict, NotFound
from servostudio.services.projects import layout
from servostudio.services.projects.fsutil import atomic_write
from servostudio.services.projects.names import check_name, name_taken, timestamp_name
from servostudio.services.projects.store import ProjectStore
from servostudio.services.scope.capture import Capture
from servostudio.services.scope.capturefile import (
    CaptureFileError,
    capture_csv,
    capture_sidecar,
    parse_capture,
    read_sidecar,
)


class CaptureNotFound(NotFound):
    """No saved capture of that name on the axis."""


class CaptureExists(Conflict):
    """A saved capture of that name exists on the axis already."""


@dataclass(frozen=True)
class SavedCapture:
    """What a list of saved captures shows; ``error`` names the damage of a sidecar that cannot be read."""

    name: str
    captured_at: str = ""
    channels: tuple[str, ...] = ()
    samples: int = 0
    period_ns: int = 0
    trigger: str = ""
    source: str = ""
    error: str | None = None


class CaptureStore:
    def __init__(self, projects: ProjectStore) -> None:
        self.projects = projects

    def save(self, project: str, axis: str, capture: Capture, name: str | None = None) -> Capture:
        """Save ``capture`` under ``name`` (default: its time of capture); a taken name is refused."""
        with self.projects.edit(project) as edit:
            directory = edit.axis_directory(axis) / layout.CAPTURES_DIR
            chosen = check_name(name, "capture") if name else timestamp_name(directory, capture.captured_at, "capture")
            if name and name_taken(directory, chosen):
                raise CaptureExists(f"axis '{axis}' has a capture named '{chosen}' already; choose another name")
            directory.mkdir(parents=True, exist_ok=True)
            atomic_write(directory / f"{chosen}.csv", capture_csv(capture))
            atomic_write(directory / f"{chosen}.json", capture_sidecar(capture, f"{chosen}.csv"))
        return replace(capture, name=chosen)

    def list(self, project: str, axis: str) -> list[SavedCapture]:
        with self.projects.read(project) as view:
            directory = view.axis_directory(axis) / layout.CAPTURES_DIR
            sidecars = sorted(directory.glob("*.json")) if directory.is_dir() else []
            return [_summary(path, axis) for path in sidecars if not path.name.startswith(layout.TEMP_PREFIX)]

    def open(self, project: str, axis: str, name: str) -> Capture:
        with self.projects.read(project) as view:
            csv_path, json_path = self._paths(view.axis_directory(axis), axis, name)
            csv_label, json_label = _label(axis, csv_path), _label(axis, json_path)
            capture = parse_capture(_text(csv_path, csv_label), _text(json_path, json_label), csv_label, json_label)
        return replace(capture, name=name)

    def delete(self, project: str, axis: str, name: str) -> None:
        with self.projects.edit(project) as edit:
            csv_path, json_path = self._paths(edit.axis_directory(axis), axis, name)
            json_path.unlink()  # the capture is gone once its sidecar is
            csv_path.unlink(missing_ok=True)

    def _paths(self, axis_directory: Path, axis: str, name: str) -> tuple[Path, Path]:
        check_name(name, "capture")
        directory = axis_directory / layout.CAPTURES_DIR
        json_path = directory / f"{name}.json"
        if not json_path.is_file():
            raise CaptureNotFound(f"axis '{axis}' has no saved capture '{name}'")
        return directory / f"{name}.csv", json_path


def _summary(path: Path, axis: str) -> SavedCapture:
    label = _label(axis, path)
    try:
        header = read_sidecar(_text(path, label), label)
    except CaptureFileError as error:
        return SavedCapture(path.stem, error=str(error))
    return SavedCapture(
        name=path.stem,
        captured_at=header.captured_at,
        channels=tuple(channel.key for channel in header.channels),
        samples=header.samples,
        period_ns=header.period_ns,
        trigger=header.trigger,
        source=header.source,
    )


def _label(axis: str, path: Path) -> str:
    """How messages name a capture file: by its place in the project, never by a server path."""
    return f"{axis}/{layout.CAPTURES_DIR}/{path.name}"


def _text(path: Path, label: str) -> str:
    try:
        data = path.read_bytes()
    except FileNotFoundError:
        raise CaptureFileError(f"{label}:1: the file is missing") from None
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as error:
        line = data[: error.start].count(b"\n") + 1
        raise CaptureFileError(f"{label}:{line}: not UTF-8 text ({error.reason})") from None
