"""One run of a signature-started procedure on a drive: start it, follow its status, abort it, turn its end into a
result or a failure that names the drive's fault and the likely cause.

Every procedure runs the same way (docs/commissioning.md §1): write the start signature to the trigger, read the
trigger's status until it is no longer 2 "running" (progress events meanwhile), and on status 1 or 4 ask the drive
why (its fault report, the values the procedure needed); an abort writes 0 to the trigger, leaves the drive disabled
and puts the values the procedure changed back as they were.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field

from servostudio.drive.access import Drive
from servostudio.drive.cia402 import State
from servostudio.drive.control import fault_report, read_state, set_state
from servostudio.drive.profiles import signature_value
from servostudio.drive.profiles.procedures import STATUSES, ProcedureDescription
from servostudio.drive.sdo import settle
from servostudio.errors import CommunicationError, RefusedForSafety, Timeout
from servostudio.od.model import Variable
from servostudio.services.cancel import Cancellation, Cancelled
from servostudio.services.procedures.preconditions import preconditions

POLL_SECONDS = 0.1
ABORT_WAIT = 3.0
RUNNING, DONE = 2, 5
Report = Callable[[dict[str, object]], None]
Values = dict[str, object]


class ProcedureFailed(CommunicationError):
    """The drive ran the procedure and it failed (status 1 or 4): the message names its fault and the likely cause."""


class ProcedureTimeout(Timeout):
    """The procedure did not end in time; it was aborted."""


class ControllerGone(RefusedForSafety):
    """The axis's controller went away while the procedure turned the motor: it was aborted."""


def status_name(code: int | None) -> str:
    return STATUSES[code] if code is not None and 0 <= code < len(STATUSES) else "unknown"


@dataclass
class ProcedureRun:
    """One run: the drive, which procedure, where its progress goes, and how it is stopped."""

    drive: Drive
    name: str
    description: ProcedureDescription
    report: Report
    cancellation: Cancellation
    #: False once the axis's controller is gone (a moving procedure is then aborted)
    controlled: Callable[[], bool] = lambda: True
    started: float = field(default_factory=time.monotonic)

    @property
    def elapsed(self) -> float:
        return time.monotonic() - self.started

    def progress(self, phase: str, status: str, message: str, fraction: float | None = None) -> None:
        self.report(
            {
                "type": "progress",
                "operation": f"procedure:{self.name}",
                "procedure": self.name,
                "node": self.drive.node,
                "phase": phase,
                "status": status,
                "elapsed_s": round(self.elapsed, 3),
                "fraction": fraction,
                "message": message,
            }
        )

    def status(self) -> int | None:
        raw = self.drive.read(self.description.trigger).raw
        return raw if isinstance(raw, int) else None

    def execute(self, writes: Sequence[tuple[Variable, object]]) -> int:
        """Write the options, start, and wait for the end; returns the final status (done, cannot, error, aborted).
        Cancellation and a lost controller abort it (raising), a timeout too."""
        if writes:
            settle(self.drive.submit_write_all(list(writes)).future)
        self.cancellation.check(f"{self.description.label} started")
        self.drive.write(self.description.trigger, signature_value(self.description.signature))
        self.progress("running", "running", f"{self.description.label} started", 0.0)
        return self._follow()

    def _follow(self) -> int:
        deadline = self.started + self.description.timeout_s
        while True:
            code = self.status()
            if code != RUNNING:
                return code if code is not None else -1
            if self.cancellation.requested:
                raise Cancelled(f"{self.description.label} aborted by its client")
            if not self.controlled():
                raise ControllerGone(
                    f"node {self.drive.node}: the axis's controller went away: {self.description.label} aborted"
                )
            if time.monotonic() > deadline:
                raise ProcedureTimeout(
                    f"node {self.drive.node}: {self.description.label} still running after "
                    f"{self.description.timeout_s:g} s: aborted"
                )
            fraction = min(self.elapsed / self.description.duration_s, 0.95)
            self.progress("running", "running", f"{self.description.label} running", round(fraction, 3))
            time.sleep(POLL_SECONDS)

    def abort(self) -> None:
        """Write 0 to the trigger and wait until it no longer runs; the drive is left disabled."""
        self.drive.write(self.description.trigger, 0)
        deadline = time.monotonic() + ABORT_WAIT
        while self.status() == RUNNING and time.monotonic() < deadline:
            time.sleep(POLL_SECONDS / 2)
        disable(self.drive)

    def failure(self, code: int) -> ProcedureFailed:
        """What a status other than done means, with the drive's own reasons."""
        label = f"node {self.drive.node}: {self.description.label}"
        if code == 1:
            unmet = [item.reason for item in preconditions(self.drive, self.name, self.description) if not item.ok]
            why = "; ".join(reason for reason in unmet if reason) or "the drive gives no reason the tool can see"
            return ProcedureFailed(f"{label}: the drive answered 'cannot execute': {why}")
        if code == 3:
            return ProcedureFailed(f"{label} was aborted (0 written to its trigger by another client)")
        return ProcedureFailed(f"{label} stopped on error: {fault_cause(self.drive)}")


def fault_cause(drive: Drive) -> str:
    """The drive's faults, their remedies and the values the tool sees missing."""
    report = fault_report(drive)
    faults = "; ".join(f"{fault.name} ({fault.remedy})" if fault.remedy else fault.name for fault in report.faults)
    causes = "; ".join(cause.text for cause in report.causes)
    likely = (
        f"; likely cause: {causes}"
        if causes
        else ("; likely cause: the shaft is blocked or loaded (brake, coupled load), or a limit switch became active")
    )
    return (faults or report.error_text or f"status word 0x{report.statusword:04X}") + likely


def disable(drive: Drive) -> None:
    """Leave the power stage off (an enabled axis, e.g. auto-tuning at standstill or a verification, is shut down)."""
    state, _ = read_state(drive)
    if state in (State.OPERATION_ENABLED, State.QUICK_STOP_ACTIVE):
        set_state(drive, State.READY_TO_SWITCH_ON)


def read_values(drive: Drive, names: Sequence[str]) -> Values:
    """The raw values of the named objects the drive has, in one batch."""
    present = [name for name in names if _known(drive, name)]
    variables = [drive.variable(name) for name in present]
    values = settle(drive.submit_read_all(variables).future) if variables else []
    return {
        name: value.raw for name, value in zip(present, values, strict=True) if not isinstance(value, BaseException)
    }


def restore(drive: Drive, before: Mapping[str, object]) -> Values:
    """Write back what changed since ``before``; returns the values read back."""
    now = read_values(drive, list(before))
    changed = [(drive.variable(name), value) for name, value in before.items() if now.get(name) != value]
    if changed:
        settle(drive.submit_write_all(changed).future)
    return read_values(drive, list(before))


def _known(drive: Drive, name: str) -> bool:
    """The drive has the object and it can be read (the CD1-k's modes of operation 0x6060 is write-only)."""
    if not drive.profile.has(name) or drive.dictionary is None:
        return False
    variable = drive.dictionary.get(*drive.profile.address(name))
    return variable is not None and variable.access.readable
