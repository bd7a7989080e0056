"""The frequency-response service: one implementation behind the REST route, its job and the CLI.

``check`` refuses before anything is written (bad request 422, a drive whose response cannot come back — a plant
through TPDOs without a current actual value, a bus too slow for the SYNC rate's frames — 422, no armed controller
409, unknown project or axis 404); ``run`` measures (``measure.py``), adds who, what and when, and saves the result
under the axis when the request names project and axis (``store.py``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from datetime import UTC, datetime
from typing import Any

from servostudio.drive.access import Drive
from servostudio.services.audit import current_actor
from servostudio.services.bus import BusConnection, Job, JobRegistry
from servostudio.services.cancel import Cancellation
from servostudio.services.frequency import store
from servostudio.services.frequency.measure import MeasureRequest, Report, check_request, measure
from servostudio.services.motion import MotionGuard
from servostudio.services.procedures.store import IncompleteTarget
from servostudio.services.projects.store import ProjectStore

Axis = tuple[str, int]
OPERATION = "frequency-response"


@dataclass(frozen=True)
class FrequencyRequest:
    measure: MeasureRequest = field(default_factory=MeasureRequest)
    project: str | None = None
    axis: str | None = None


class FrequencyService:
    def __init__(self, projects: ProjectStore | None = None) -> None:
        self.projects = projects

    def check(
        self, motion: MotionGuard, axis: Axis, drive: Drive, request: FrequencyRequest, bitrate: int | None = None
    ) -> None:
        check_request(drive, request.measure, bitrate)
        motion.require_controller(current_actor(), axis, "the frequency response turns the motor")
        self._check_target(request)

    def start(
        self, jobs: JobRegistry, motion: MotionGuard, connection: BusConnection, drive: Drive, request: FrequencyRequest
    ) -> Job:
        self.check(motion, (connection.id, drive.node), drive, request, connection.spec.bitrate)

        def work(progress: Callable[[dict[str, object]], None], cancellation: Cancellation) -> object:
            report = _on_axis(progress, connection.id, drive.node)
            return self.run(motion, connection, drive, request, report, cancellation)

        # the measurement borrows the node's last RPDO and its recorder or TPDOs, and sends the bus's SYNC
        return connection.claims.start((drive.node,), lambda: jobs.start(OPERATION, work), sync=True)

    def run(
        self,
        motion: MotionGuard,
        connection: BusConnection,
        drive: Drive,
        request: FrequencyRequest,
        report: Report,
        cancellation: Cancellation,
    ) -> dict[str, Any]:
        """The whole measurement (what the job runs; the CLI calls it directly)."""
        axis = (connection.id, drive.node)
        self.check(motion, axis, drive, request, connection.spec.bitrate)
        actor = current_actor()
        when = datetime.now(UTC).isoformat(timespec="seconds").replace("+00:00", "Z")
        outcome = measure(
            drive,
            connection.link,
            request.measure,
            report,
            cancellation,
            _controlled(motion, axis, actor.client),
            lambda why: motion.quick_stop(axis, drive, f"frequency response: {why}", running=True),
            connection.nmt_state(drive.node) == "OPERATIONAL",
            connection.spec.bitrate,
        )
        result = {
            "kind": outcome.pop("kind"),
            "loop": outcome.pop("loop"),
            "node": drive.node,
            "device": drive.profile.device,
            "axis": request.axis,
            "time": when,
            "user": actor.user,
            **outcome,
        }
        result["saved"] = self._save(request, result)
        report({"stage": "done", "fraction": 1.0, "aborted": result["aborted"]})
        return result

    def _check_target(self, request: FrequencyRequest) -> None:
        if request.project is None and request.axis is None:
            return
        if request.project is None or request.axis is None or self.projects is None:
            raise IncompleteTarget("a result is saved under a project's axis: give both project and axis")
        with self.projects.read(request.project) as view:
            view.axis(request.axis)

    def _save(self, request: FrequencyRequest, result: dict[str, Any]) -> str | None:
        if self.projects is None or request.project is None or request.axis is None:
            return None
        return store.save(self.projects, request.project, request.axis, result)


def _controlled(motion: MotionGuard, axis: Axis, client: str | None) -> Callable[[], bool]:
    """Whether the client that started the measurement still holds the axis."""

    def holds() -> bool:
        holder = motion.controllers.holder(axis)
        return client is None or (holder is not None and holder.client == client)

    return holds


def _on_axis(progress: Callable[[dict[str, object]], None], bus: str, node: int) -> Report:
    return lambda event: progress({"type": "progress", "operation": OPERATION, "bus": bus, "node": node, **event})
