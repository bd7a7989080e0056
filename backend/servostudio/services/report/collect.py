"""What the commissioning report shows, read from the project's files alone (no drive, no server): the project file,
the axis files, the saved procedure results, frequency responses and captures, and, when one is at hand, the
audit log. Nothing here computes a value the files do not hold; the sections say what is missing.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from servostudio.od import LibraryError, ObjectDictionary
from servostudio.services.audit import AuditLog, AuditQuery
from servostudio.services.frequency import store as frequency_store
from servostudio.services.procedures.store import ResultStore
from servostudio.services.projects import Axis, Motor, ParameterRow, Project, ProjectNotFound, ProjectService, layout
from servostudio.services.projects.store import setting_files

#: the audit entries the history shows at most (the newest), per project
HISTORY_LIMIT = 200


@dataclass(frozen=True)
class FileSum:
    """One settings file of the project: its place, size and SHA-256, and its first comment line (a backup's
    header names the node and the time it was read)."""

    path: str
    size: int
    sha256: str
    header: str


@dataclass(frozen=True)
class AxisRecord:
    axis: Axis
    bus_interface: str
    dictionary: ObjectDictionary | None
    identity: dict[str, Any] | None  # the drive as a saved capture identified it (serial, software version)
    identity_source: str
    motor: Motor | None
    motor_rows: list[ParameterRow]
    procedures: list[dict[str, Any]]  # saved results, newest first, each with ``file`` and ``saved_at``
    frequency: list[dict[str, Any]]  # saved frequency responses with their points, newest first
    differing: list[ParameterRow]
    files: list[FileSum]
    history: list[dict[str, Any]]


@dataclass(frozen=True)
class ProjectRecord:
    project: Project
    revision: str
    axes: list[AxisRecord]
    files: list[FileSum]  # the project's own files (project.toml)
    history: list[dict[str, Any]]  # the audit entries of the project itself (not of one axis), newest first
    audit_available: bool
    generated_at: str


def collect(
    projects: ProjectService, name: str, axis: str | None = None, audit: AuditLog | None = None
) -> ProjectRecord:
    """Everything the report of a project (or of one of its axes) shows."""
    snapshot = projects.store.open(name)
    project = snapshot.project
    chosen = [_axis(project, axis)] if axis is not None else list(project.axes)
    directory = projects.store.project_directory(project.name)
    sums = _checksums(directory)
    history = _history(audit, project.name)
    return ProjectRecord(
        project=project,
        revision=snapshot.revision,
        axes=[_axis_record(projects, project, item, sums, history) for item in chosen],
        files=[item for item in sums if "/" not in item.path],
        history=[entry for entry in history if not entry.get("project_axis")],
        audit_available=audit is not None,
        generated_at=datetime.now(UTC).strftime("%Y-%m-%dT%H:%M:%SZ"),
    )


def _axis(project: Project, name: str) -> Axis:
    found = next((item for item in project.axes if item.name.casefold() == name.casefold()), None)
    if found is None:
        known = ", ".join(item.name for item in project.axes) or "none"
        raise ProjectNotFound(f"project '{project.name}' has no axis '{name}' (axes: {known})")
    return found


def _axis_record(
    projects: ProjectService, project: Project, axis: Axis, sums: list[FileSum], history: list[dict[str, Any]]
) -> AxisRecord:
    directory = projects.store.project_directory(project.name) / axis.name
    identity, source = _identity(directory / layout.CAPTURES_DIR)
    differing, _ = projects.parameters.rows(project.name, axis.name, only_differences=True)
    return AxisRecord(
        axis=axis,
        bus_interface=project.bus_of(axis).interface,
        dictionary=_dictionary(projects, axis),
        identity=identity,
        identity_source=source,
        motor=_motor(projects, axis),
        motor_rows=[row for row in differing if row.variable.group.casefold() == "motor"],
        procedures=[_dated(result) for result in ResultStore(projects.store).list(project.name, axis.name)],
        frequency=_frequency(directory.parent, axis.name),
        differing=differing,
        files=[item for item in sums if item.path.split("/", 1)[0] == axis.name],
        history=[entry for entry in history if entry.get("project_axis") == axis.name],
    )


def _dictionary(projects: ProjectService, axis: Axis) -> ObjectDictionary | None:
    try:
        return projects.library.load(axis.device)
    except LibraryError:
        return None


def _motor(projects: ProjectService, axis: Axis) -> Motor | None:
    if not axis.motor:
        return None
    try:
        return projects.motors.get(axis.motor)
    except ProjectNotFound:
        return None


def _dated(result: dict[str, Any]) -> dict[str, Any]:
    """A saved result with the UTC time its file name carries (``auto_tuning-20261202T050102.123456Z.json``)."""
    stamp = str(result.get("file", "")).rsplit("-", 1)[-1].removesuffix(".json")
    try:
        saved = datetime.strptime(stamp, "%Y%m%dT%H%M%S.%fZ").strftime("%Y-%m-%dT%H:%M:%SZ")
    except ValueError:
        saved = None
    return {**result, "saved_at": result.get("time") or saved}


def _frequency(project_dir: Path, axis: str) -> list[dict[str, Any]]:
    """Every saved frequency response with its points; a damaged one keeps its name and the reason."""
    loaded = []
    for summary in frequency_store.list_saved(project_dir, axis):
        if summary.get("error"):
            loaded.append(summary)
            continue
        try:
            loaded.append(frequency_store.load(project_dir, axis, str(summary["name"])))
        except frequency_store.FrequencyFileError as error:
            loaded.append({"name": summary["name"], "error": str(error)})
    return loaded


def _identity(captures: Path) -> tuple[dict[str, Any] | None, str]:
    """The drive as the newest saved capture names it (vendor, product, revision, serial, software version)."""
    found: list[tuple[str, str, dict[str, Any]]] = []
    for path in sorted(captures.glob("*.json")) if captures.is_dir() else []:
        try:
            sidecar = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            continue
        if isinstance(sidecar, dict) and isinstance(sidecar.get("drive"), dict):
            found.append((str(sidecar.get("captured_at", "")), path.stem, sidecar["drive"]))
    if not found:
        return None, ""
    captured_at, name, drive = max(found, key=lambda item: item[0])
    return drive, f"saved capture '{name}' of {captured_at}"


def _checksums(directory: Path) -> list[FileSum]:
    return [_sum(directory, path) for path in setting_files(directory)]


def _sum(directory: Path, path: Path) -> FileSum:
    data = path.read_bytes()
    first = data.split(b"\n", 1)[0].decode("latin-1").strip()
    header = first.lstrip(";#").strip() if first[:1] in (";", "#") else ""
    relative = path.relative_to(directory).as_posix()
    return FileSum(relative, len(data), hashlib.sha256(data).hexdigest(), header)


def _history(audit: AuditLog | None, project: str) -> list[dict[str, Any]]:
    """The project's entries of the audit log, newest first (the log is the server's, not the project's)."""
    if audit is None:
        return []
    return audit.entries(AuditQuery(project=project, limit=HISTORY_LIMIT)).entries
