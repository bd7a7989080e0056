"""Tool-side identification (issue #16 item 4; docs/identification.md): the experiment run through the motion guard
as a job, the plant estimated from its recording, the result in the same keys as auto-tuning's ``identified``.

``start`` refuses before anything is written (bad options or a profile that leaves the position window 422, no
armed controller of the axis 409), then the job runs the experiment acting as that controller: every write goes
through the bus's write gate, and the run ends with a quick stop when the controller goes away.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field, replace
from datetime import UTC, datetime
from typing import Any

from servostudio.drive.access import Drive
from servostudio.services.audit import current_actor
from servostudio.services.bus import BusConnection, Job, JobRegistry
from servostudio.services.cancel import Cancellation
from servostudio.services.identification.estimator import best_fit, estimate
from servostudio.services.identification.experiment import BadExperiment, ExperimentOptions, check_fits, run_experiment
from servostudio.services.identification.tuning import check_tuning, tune
from servostudio.services.motion import MotionGuard

Axis = tuple[str, int]
Report = Callable[[dict[str, object]], None]
OPERATION = "identification"


@dataclass(frozen=True)
class IdentificationRequest:
    options: Mapping[str, Any] = field(default_factory=dict)
    #: tune the speed loop for this bandwidth afterwards (drives with gain objects), and verify it by a step
    bandwidth_hz: float | None = None


def options_of(request: IdentificationRequest) -> ExperimentOptions:
    known = set(ExperimentOptions.__dataclass_fields__)
    unknown = sorted(set(request.options) - known)
    if unknown:
        raise BadExperiment(f"unknown identification options: {', '.join(unknown)} (known: {', '.join(sorted(known))})")
    try:
        return ExperimentOptions(**{key: float(value) for key, value in request.options.items()})
    except (TypeError, ValueError) as error:
        raise BadExperiment(f"identification options: {error}") from None


def check(
    motion: MotionGuard, axis: Axis, request: IdentificationRequest, drive: Drive | None = None
) -> ExperimentOptions:
    """Everything that refuses a start, before anything is written (with ``drive``: the tuning's too)."""
    options = options_of(request)
    check_fits(options)
    if drive is not None:
        check_tuning(drive, request.bandwidth_hz)
    motion.require_controller(current_actor(), axis, "the identification turns the motor")
    return options


def start(jobs: JobRegistry, motion: MotionGuard, connection: BusConnection, drive: Drive,
          request: IdentificationRequest) -> Job:  # fmt: skip
    axis = (connection.id, drive.node)
    options = check(motion, axis, request, drive)

    def work(progress: Report, cancellation: Cancellation) -> object:
        report = _on_axis(progress, connection.id, drive.node)
        return identify(motion, axis, drive, options, report, cancellation, request.bandwidth_hz)

    # the experiment records through the node's TPDOs at the server's SYNC (services/scope, source tpdo)
    return connection.claims.start((drive.node,), lambda: jobs.start(OPERATION, work), sync=True)


def identify(motion: MotionGuard, axis: Axis, drive: Drive, options: ExperimentOptions, report: Report,
             cancellation: Cancellation, bandwidth_hz: float | None = None) -> dict[str, object]:  # fmt: skip
    """The experiment and the estimate, then the tuning when a bandwidth is asked for (what a job runs; the CLI calls
    it after ``check``)."""
    holds = _holds(motion, axis, client=current_actor().client)
    with _loop_set_for_the_axis(drive, options, report, cancellation, holds) as share:
        record, facts = run_experiment(drive, options, _progress(report, *share), cancellation, holds)
    report({"phase": "estimating", "fraction": 0.95, "message": "least-squares estimate"})
    plant = estimate(record)
    identified: dict[str, object] = {**plant.as_dict(), "inertia_ratio": _ratio(drive, plant.inertia_kgm2)}
    result = {
        "kind": "identification",
        "status": "done",
        "node": drive.node,
        "device": drive.profile.device,
        "time": datetime.now(UTC).isoformat(timespec="seconds").replace("+00:00", "Z"),
        "identified": identified,
        "experiment": {
            **options.as_dict(),
            **facts,
            "segments": plant.rows,
            "torque_shift_samples": plant.torque_shift_samples,
        },
    }
    if bandwidth_hz is not None:
        cancellation.check("identification")
        result["tuning"] = tune(drive, identified, bandwidth_hz, report)
    report({"phase": "done", "fraction": 1.0, "message": "identification done"})
    return result


def _ratio(drive: Drive, inertia: float) -> float | None:
    """Total inertia over the motor's own (motor data), where the drive has it."""
    name = drive.profile.procedures.motor_inertia
    if name is None or not drive.profile.has(name) or inertia <= 0:
        return None
    motor = float(drive.read(name).physical)
    return round(inertia / motor, 3) if motor > 0 else None


def _holds(motion: MotionGuard, axis: Axis, client: str | None) -> Callable[[], bool]:
    def holds() -> bool:
        holder = motion.controllers.holder(axis)
        return client is None or (holder is not None and holder.client == client)

    return holds


@contextlib.contextmanager
def _loop_set_for_the_axis(drive: Drive, options: ExperimentOptions, report: Report, cancellation: Cancellation,
                           holds: Callable[[], bool]) -> Iterator[tuple[float, float]]:  # fmt: skip
    """A drive that derives its speed loop from an inertia setting (the encoTRive's Θi) ships with its rotor's: on
    a heavy axis the loop is then several times softer than designed, and the friction the holds show is lost in
    its ripple (viscous friction 0.33–0.96 × true on seed 3 under load, 0.94–1.11 with Θi at the true inertia). So
    a one-cycle pass finds the inertia first, the setting is made that for the experiment and put back after it.
    Yields the share of the progress bar the experiment itself fills (start, span)."""
    speed_loop = drive.profile.speed_loop
    setting = speed_loop.inertia_setting if speed_loop is not None else None
    if setting is None:
        yield 0.0, 0.9
        return
    first, _ = run_experiment(drive, replace(options, cycles=1), _progress(report, 0.0, 0.3), cancellation, holds)
    inertia = best_fit(first).inertia_kgm2
    if inertia <= 0:  # a first pass that found no inertia: the experiment on the drive's own setting says why
        yield 0.3, 0.6
        return
    before = drive.read(setting.object).raw
    drive.write(setting.object, max(1, round(inertia / setting.unit_kgm2)))
    try:
        yield 0.3, 0.6
    finally:
        drive.write(setting.object, before)


def _progress(report: Report, start: float = 0.0, span: float = 0.9) -> Callable[[str, float], None]:
    return lambda message, fraction: report({"phase": "running", "fraction": round(start + fraction * span, 3),
                                              "message": message})  # fmt: skip


def _on_axis(progress: Report, bus: str, node: int) -> Report:
    """Progress events name the operation, bus and node (the page follows its axis's)."""
    return lambda event: progress({"type": "progress", "operation": OPERATION, "bus": bus, "node": node, **event})
