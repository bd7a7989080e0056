"""The procedure service: the one implementation of phasing, the current-loop calculation and auto-tuning behind the
REST routes, the WebSocket progress, the CLI and the pages.

``start`` refuses before anything is written (unknown procedure 404, bad options 422, a moving procedure without the
axis's armed controller 409, an unmet precondition 409 with the manual's reason, an unknown project or axis 404),
then runs the procedure as a job (``run``): options, start, status, result, verification, saved in the project.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from servostudio.drive.access import Drive
from servostudio.drive.profiles.procedures import ProcedureDescription
from servostudio.drive.sdo import settle
from servostudio.errors import NotFound
from servostudio.services.audit import current_actor
from servostudio.services.bus import BusConnection, Job, JobRegistry
from servostudio.services.cancel import Cancellation, Cancelled
from servostudio.services.motion import MotionGuard
from servostudio.services.procedures import options as option_rules
from servostudio.services.procedures.preconditions import preconditions, require
from servostudio.services.procedures.results import aborted, before_values, shape
from servostudio.services.procedures.run import (
    DONE,
    ControllerGone,
    ProcedureRun,
    ProcedureTimeout,
    Report,
    read_values,
    restore,
    status_name,
)
from servostudio.services.procedures.store import ResultStore
from servostudio.services.procedures.undo import undo_gains
from servostudio.services.procedures.verification import verify

Axis = tuple[str, int]


class UnknownProcedure(NotFound):
    """The drive's profile has no procedure of that name."""


@dataclass(frozen=True)
class ProcedureRequest:
    options: Mapping[str, Any] = field(default_factory=dict)
    verify: bool = True
    project: str | None = None
    axis: str | None = None


def description_of(drive: Drive, name: str) -> ProcedureDescription:
    description = drive.profile.procedures.get(name)
    if description is None:
        known = ", ".join(drive.profile.procedures.procedures) or "none"
        raise UnknownProcedure(
            f"node {drive.node}: the {drive.profile.device} has no procedure {name!r} (it has {known})"
        )
    return description


def describe(drive: Drive) -> list[dict[str, object]]:
    """Every procedure of the drive with its status and preconditions as they stand now."""
    return [_described(drive, name, description) for name, description in drive.profile.procedures.procedures.items()]


def _described(drive: Drive, name: str, description: ProcedureDescription) -> dict[str, object]:
    checks = preconditions(drive, name, description)
    raw = drive.read(description.trigger).raw
    return {
        "name": name,
        "label": description.label,
        "moves": description.moves,
        "status": status_name(raw if isinstance(raw, int) else None),
        "preconditions": [item.as_dict() for item in checks],
        "ready": all(item.ok for item in checks),
    }


class ProcedureService:
    """Starts procedures as jobs; the results go to the project store when a request names project and axis."""

    def __init__(self, results: ResultStore | None = None) -> None:
        self.results = results

    def check(self, motion: MotionGuard, axis: Axis, drive: Drive, name: str, request: ProcedureRequest) -> list:
        """Everything that refuses a start, before anything is written; returns the option writes."""
        description = description_of(drive, name)
        writes = option_rules.option_writes(drive, name, description, request.options)
        if description.moves:
            motion.require_controller(current_actor(), axis, f"{description.label} turns the motor")
        if self.results is not None:
            self.results.check(request.project, request.axis)
        provided = frozenset(f"value:{description.values[key]}" for key in request.options if key in description.values)
        provided |= frozenset("value:control_inductance" for key in request.options if key == "inductance_mh")
        require(drive, name, description, provided)
        return writes

    def start(
        self, jobs: JobRegistry, motion: MotionGuard, connection: BusConnection, drive: Drive, name: str,
        request: ProcedureRequest,
    ) -> Job:  # fmt: skip
        axis = (connection.id, drive.node)
        writes = self.check(motion, axis, drive, name, request)

        def work(progress: Callable[[dict[str, object]], None], cancellation: Cancellation) -> object:
            report = _on_axis(progress, connection.id)
            return self.run(motion, axis, drive, name, request, report, cancellation, writes)

        return jobs.start(f"procedure:{name}", work)

    def run(
        self, motion: MotionGuard, axis: Axis, drive: Drive, name: str, request: ProcedureRequest, report: Report,
        cancellation: Cancellation, writes: list | None = None,
    ) -> dict[str, object]:  # fmt: skip
        """The whole procedure (what a job runs; the CLI calls it directly after ``check``)."""
        if writes is None:
            writes = self.check(motion, axis, drive, name, request)
        description = description_of(drive, name)
        actor = current_actor()
        controlled = _controlled(motion, axis, actor.client) if description.moves else _always
        run = ProcedureRun(drive, name, description, report, cancellation, controlled)
        run.progress("preconditions", status_name(run.status()), "preconditions met", 0.0)
        saved_mode = _enter_mode(drive, description)
        before = before_values(drive, description)
        try:
            result = self._run(run, before, writes, request)
        except Cancelled:
            result = self._aborted(run, before)
        except (ControllerGone, ProcedureTimeout):
            self._aborted(run, before)
            raise
        finally:
            _leave_mode(drive, saved_mode)
        result = {"procedure": name, **result, "options": option_rules.shown(name, request.options)}
        result["saved"] = self._save(request, name, result)
        run.progress("done", str(result["status"]), f"{description.label} {result['status']}", 1.0)
        return result

    def _run(self, run: ProcedureRun, before: dict, writes: list, request: ProcedureRequest) -> dict[str, object]:
        code = run.execute(writes)
        if code != DONE:
            raise run.failure(code)
        run.progress("reading", "done", f"{run.description.label} done: reading the result", None)
        result = shape(run.drive, run.name, run.description, before)
        if request.verify:
            checked = verify(run, result, request.options)
            if checked is not None:
                result["verification"] = checked
        if run.cancellation.requested:  # aborted while it verified: the gains go back all the same
            raise Cancelled(f"{run.description.label} aborted by its client")
        return result

    def _aborted(self, run: ProcedureRun, before: dict) -> dict[str, object]:
        run.abort()
        now = restore(run.drive, before)
        return aborted(run.description, before, now)

    def _save(self, request: ProcedureRequest, name: str, result: dict[str, object]) -> str | None:
        if self.results is None or request.project is None or request.axis is None:
            return None
        return self.results.save(request.project, request.axis, name, result)

    def undo(self, drive: Drive, gains: Mapping[str, object]) -> dict[str, object]:
        return undo_gains(drive, description_of(drive, "auto_tuning"), gains)

    def saved(self, project: str, axis: str) -> list[dict[str, object]]:
        if self.results is None:
            return []
        return self.results.list(project, axis)


def _enter_mode(drive: Drive, description: ProcedureDescription) -> object | None:
    """Switch to the mode the procedure runs in; returns the mode to go back to (None: unchanged)."""
    if description.mode is None or not drive.profile.has("modes_of_operation"):
        return None
    present = read_values(drive, ["modes_of_operation_display"]).get("modes_of_operation_display")
    if present == description.mode:
        return None
    drive.write("modes_of_operation", description.mode)
    return present


def _leave_mode(drive: Drive, mode: object | None) -> None:
    if mode is not None:
        settle(drive.submit_write("modes_of_operation", mode))


def _controlled(motion: MotionGuard, axis: Axis, client: str | None) -> Callable[[], bool]:
    """Whether the client that started the run still holds the axis (always, for one that needs no controller)."""

    def holds() -> bool:
        holder = motion.controllers.holder(axis)
        return client is None or (holder is not None and holder.client == client)

    return holds


def _always() -> bool:
    """A procedure that does not move needs no controller."""
    return True


def _on_axis(progress: Callable[[dict[str, object]], None], bus: str) -> Report:
    """Procedure progress events name the bus too (the page follows its axis's)."""
    return lambda event: progress({**event, "bus": bus})
