"""Commission from a project: check every axis's drive, then download the project to the drives or upload the
drives into the project. One report per axis; an axis that fails does not stop the others.

Download makes each drive hold the project's values: a drive freshly loaded with the axis files holds the file
values and the dictionary default of everything else (docs/projects.md §4), so the files sent are *complete* — every
object drive and project exchange, with its project value — and go through ``services.backup.restore_file``
(validated as a whole before the first write, written, read back, stored to flash). Objects the project gives no
value (no default, not set) are not sent and keep the drive's value; the report counts them. A sequence file
(SEQUENCE.TXT, a TTA-PRO's TTASEQ.TXT) is restored as the project holds it (an empty file clears the drive's
sequences).

Upload reads the drives' files with ``services.backup.backup_drive`` into a scratch directory, checks them against
the axis's dictionary, and then replaces the axis files of every uploaded axis in one project change.

A cancellation stops a download at the next object (the axis's file result says what was written) and an upload
at the next file; a cancelled upload changes nothing in the project.
"""

from __future__ import annotations

import contextvars
import logging
import shutil
import tempfile
import time
from collections.abc import Callable, Iterable, Mapping
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

from servostudio.drive.access import Drive
from servostudio.drive.sdo import LARGE_SAFETY_WAIT, OutcomeOverdue, settle
from servostudio.errors import ServoStudioError
from servostudio.formats.objectfile import ObjectEntry, format_object_file, write_object_file
from servostudio.services.backup import FileKind, backup_drive, drive_file_kinds, restore_file
from servostudio.services.bus import ConnectionManager
from servostudio.services.cancel import Cancellation
from servostudio.services.projects import layout
from servostudio.services.projects.axisvalues import AxisValues
from servostudio.services.projects.errors import ConflictError, ProjectError, ValidationError
from servostudio.services.projects.live.links import AxisLink, link_axes
from servostudio.services.projects.parameter_values import to_file_value
from servostudio.services.projects.revisions import keeping
from servostudio.services.projects.service import ProjectService

log = logging.getLogger(__name__)
Progress = Callable[[dict[str, object]], None]
DIRECTIONS = ("check", "download", "upload")
#: Safety net of the wait for one axis's download or upload: every transfer of it has its own timeout, so this only
#: ends the wait when a bus reader is stuck (a whole axis over the 19200-baud RS-232 link takes well under it)
AXIS_SAFETY_WAIT = 2 * LARGE_SAFETY_WAIT


@dataclass
class AxisReport:
    link: AxisLink
    files: list[dict[str, object]] = field(default_factory=list)
    error: str = ""

    @property
    def ok(self) -> bool:
        return self.link.ok and not self.error and all(item.get("ok", True) for item in self.files)

    def as_dict(self) -> dict[str, object]:
        return {**self.link.as_dict(), "ok": self.ok, "error": self.error or None, "files": self.files}


@dataclass
class CommissionReport:
    project: str
    direction: str
    axes: list[AxisReport]
    revision: str

    @property
    def ok(self) -> bool:
        return all(report.ok for report in self.axes)

    def as_dict(self) -> dict[str, object]:
        return {
            "project": self.project,
            "direction": self.direction,
            "ok": self.ok,
            "revision": self.revision,
            "axes": [report.as_dict() for report in self.axes],
        }


def commission(
    service: ProjectService,
    manager: ConnectionManager,
    project: str,
    direction: str = "check",
    axes: Iterable[str] | None = None,
    buses: Mapping[str, str] | None = None,
    expected_revision: str | None = None,
    progress: Progress | None = None,
    cancel: Cancellation | None = None,
) -> CommissionReport:
    """Check the chosen axes (all by default), then download or upload the usable ones."""
    if direction not in DIRECTIONS:
        raise ValidationError(f"direction must be one of {', '.join(DIRECTIONS)}, not {direction!r}")
    snapshot = service.store.open(project)
    if expected_revision is not None and snapshot.revision != expected_revision:
        raise ConflictError(project, expected_revision, snapshot.revision)
    links = link_axes(snapshot.project, manager, axes, buses)
    reports = [AxisReport(link) for link in links]
    usable = [report for report in reports if report.link.ok]
    _notify(progress, project, "identified", [link.as_dict() for link in links])
    with tempfile.TemporaryDirectory(prefix="servostudio-commission-") as scratch:
        if direction == "download":
            copies = _copy_axis_files(service, project, [report.link for report in usable], Path(scratch))
            _parallel(
                usable,
                lambda report: _download(
                    report, copies[report.link.axis.name], Path(scratch), progress, project, cancel
                ),
            )
        elif direction == "upload":
            _parallel(
                usable, lambda report: _backup(report, Path(scratch) / report.link.axis.name, progress, project, cancel)
            )
            if cancel is not None and cancel.requested:
                for report in usable:
                    report.error = report.error or "upload cancelled; the project was not changed"
                return CommissionReport(project, direction, reports, service.store.open(project).revision)
            revision = _install(
                service,
                project,
                [r for r in usable if not r.error],
                Path(scratch),
                expected_revision or snapshot.revision,
            )
            return CommissionReport(project, direction, reports, revision)
    return CommissionReport(project, direction, reports, service.store.open(project).revision)


# ---- download ---------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class _AxisCopy:
    directory: Path  # the axis's files as they were when the download started
    values: AxisValues


def _copy_axis_files(
    service: ProjectService, project: str, links: list[AxisLink], scratch: Path
) -> dict[str, _AxisCopy]:
    """Snapshot the axis files under the project's read lock, so the download sends one consistent state."""
    copies = {}
    with service.store.read(project) as view:
        for link in links:
            source, target = view.axis_directory(link.axis.name), scratch / "project" / link.axis.name
            shutil.copytree(source, target, ignore=shutil.ignore_patterns(f"{layout.TEMP_PREFIX}*"))
            values = service.parameters.axis_values(view, link.axis.name)
            copies[link.axis.name] = _AxisCopy(target, values)
    return copies


def _download(
    report: AxisReport,
    copy: _AxisCopy,
    scratch: Path,
    progress: Progress | None,
    project: str,
    cancel: Cancellation | None = None,
) -> None:
    drive = report.link.drive()
    relay = _relay(progress, project, report.link)
    outgoing = scratch / "download" / report.link.axis.name
    outgoing.mkdir(parents=True)
    for kind in drive_file_kinds(drive):
        if cancel is not None and cancel.requested:
            return  # files not started are left out of the report
        if kind.save_type is None:  # a sequence file: the project keeps it whole
            source = copy.directory / kind.value
            if not source.is_file():
                continue
            result = restore_file(drive, source, kind, relay, cancel=cancel).as_dict()
        else:
            path = outgoing / kind.value
            left_out = _complete_file(copy.values, kind, path)
            result = restore_file(drive, path, kind, relay, cancel=cancel).as_dict()
            result["not_in_project"] = left_out
        result["file"] = kind.value
        report.files.append(result)
        if not result["ok"]:
            return  # later files would be stored on top of a failed one


def _complete_file(values: AxisValues, kind: FileKind, path: Path) -> list[str]:
    """Write every exchanged object of this file's save type with its project value; return the objects left out
    (no project value, or a text the object file cannot spell)."""
    entries, left_out = [], []
    for variable in values.transferable():
        if variable.save_type is not kind.save_type:
            continue
        value = values.value(variable)
        entry = (
            ObjectEntry(variable.index, variable.subindex, to_file_value(variable, value))
            if value is not None
            else None
        )
        if entry is not None and isinstance(entry.value, str):
            try:
                format_object_file([entry])
            except ValueError:
                entry = None
        if entry is None:
            left_out.append(variable.label)
        else:
            entries.append(entry)
    write_object_file(
        path,
        entries,
        header=f"{kind.value}: project values for {values.dictionary.device} node "
        f"{values.node_id}, Servo Studio download",
    )
    return left_out


# ---- upload -----------------------------------------------------------------------------------------------------


def _backup(
    report: AxisReport, directory: Path, progress: Progress | None, project: str, cancel: Cancellation | None = None
) -> None:
    drive: Drive = report.link.drive()
    results = backup_drive(drive, directory, drive_file_kinds(drive), _relay(progress, project, report.link), cancel)
    report.files = [{**result.as_dict(), "file": result.kind, "ok": True} for result in results]


def _install(
    service: ProjectService, project: str, reports: list[AxisReport], scratch: Path, expected_revision: str
) -> str:
    """Replace the uploaded axes' files in one project change (refused if the project changed meanwhile)."""
    if not reports:
        return service.store.open(project).revision
    kept = "upload of the drives into the project"  # the project as it was stays restorable (docs/projects.md §3)
    with service.store.edit(project, expected_revision) as edit, keeping(edit, kept):
        for report in reports:  # the revision check above guarantees the axes are the ones identified
            axis = report.link.axis
            try:
                AxisValues.load(scratch / axis.name, service.parameters.dictionary(axis), axis.node_id)
            except ProjectError as error:
                report.error = f"uploaded files refused: {error}"
        for report in reports:
            if report.error:
                continue
            for item in report.files:
                edit.write_axis_file(
                    report.link.axis.name,
                    str(item["file"]),
                    (scratch / report.link.axis.name / str(item["file"])).read_bytes(),
                )
    return edit.revision


# ---- helpers ----------------------------------------------------------------------------------------------------


def _parallel(reports: list[AxisReport], work: Callable[[AxisReport], None]) -> None:
    """Run ``work`` for every axis at once; a failure is recorded in that axis's report. The wait for all of them
    is bounded (`AXIS_SAFETY_WAIT`, docs/reliability.md): an axis whose work has not ended by then is reported
    overdue and not waited for, so a stuck bus reader cannot hang the commissioning job."""
    if not reports:
        return
    pool = ThreadPoolExecutor(max_workers=len(reports), thread_name_prefix="commission")
    deadline = time.monotonic() + AXIS_SAFETY_WAIT
    try:
        # each axis's thread acts for the caller (motion guard, audit log): a copy of its context apiece
        futures = [(report, pool.submit(contextvars.copy_context().run, work, report)) for report in reports]
        for report, future in futures:
            _settle_axis(report, future, deadline)
    finally:
        pool.shutdown(wait=False, cancel_futures=True)  # every future is done or overdue: nothing to wait for


def _settle_axis(report: AxisReport, future: Future[None], deadline: float) -> None:
    """Wait for one axis's work until the common deadline; its failure (or its being overdue) goes to its report."""
    try:
        settle(future, max(0.0, deadline - time.monotonic()))
    except OutcomeOverdue:
        report.error = f"no outcome of axis {report.link.axis.name} within {AXIS_SAFETY_WAIT:.0f} s; the bus is stuck"
    except Exception as error:  # reported per axis; the other axes go on; a bug is logged as well
        if not isinstance(error, ServoStudioError):
            log.exception("commission of axis %s failed unexpectedly", report.link.axis.name)
        report.error = str(error)


def _relay(progress: Progress | None, project: str, link: AxisLink) -> Progress | None:
    if progress is None:
        return None
    return lambda event: progress({**event, "project": project, "axis": link.axis.name})


def _notify(progress: Progress | None, project: str, step: str, axes: list[dict[str, object]]) -> None:
    if progress is not None:
        progress({"type": "progress", "operation": "commission", "project": project, "step": step, "axes": axes})
