"""What a procedure needs before it may start, read from the drive now, each unmet one with the manual's reason.

The drive itself answers a bad start only with status 1 "cannot execute" or, later, error 64 "procedure error";
the tool checks first (docs/commissioning.md §1): the drive disabled (or at standstill for auto-tuning), no fault,
no active limit switch, the DC bus present, the brake released, no procedure running, and the values the procedure
needs non-zero (``drive.prerequisites``). A check whose objects the drive does not have is not listed: it tells
nothing.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

from servostudio.drive.access import Drive
from servostudio.drive.cia402 import State, decode_state
from servostudio.drive.control import fault_report
from servostudio.drive.prerequisites import unmet
from servostudio.drive.profiles.procedures import ProcedureDescription
from servostudio.errors import RefusedForSafety
from servostudio.od.model import Variable
from servostudio.services.procedures.units import speed_rad_s

BUSY = 1 << 15
#: auto-tuning is refused while the axis moves; the simulated drive's standstill is |ω| < 1 rad/s
STANDSTILL_RAD_S = 1.0
_DISABLED = (State.SWITCH_ON_DISABLED, State.READY_TO_SWITCH_ON, State.SWITCHED_ON, State.NOT_READY_TO_SWITCH_ON)


class PreconditionsUnmet(RefusedForSafety):
    """A procedure was not started: what it needs is not there (nothing was written)."""


@dataclass(frozen=True)
class Precondition:
    name: str
    label: str
    ok: bool
    reason: str | None = None

    def as_dict(self) -> dict[str, object]:
        return {"name": self.name, "label": self.label, "ok": self.ok, "reason": self.reason}


Check = Callable[[Drive, str], Precondition | None]


def preconditions(drive: Drive, name: str, description: ProcedureDescription) -> list[Precondition]:
    """Every precondition of the procedure as the drive stands now."""
    checks = [CHECKS[check](drive, name) for check in description.preconditions]
    return [check for check in checks if check is not None] + _inputs(drive, name, description)


def require(drive: Drive, name: str, description: ProcedureDescription, skip: frozenset[str] = frozenset()) -> None:
    """Refuse the start, naming every unmet precondition (``skip``: inputs the request itself provides)."""
    failed = [item for item in preconditions(drive, name, description) if not item.ok and item.name not in skip]
    if failed:
        reasons = "; ".join(item.reason or item.label for item in failed)
        raise PreconditionsUnmet(f"node {drive.node}: {description.label} not started: {reasons} (nothing was written)")


def _inputs(drive: Drive, name: str, description: ProcedureDescription) -> list[Precondition]:
    """One entry per value the procedure needs non-zero and in range."""
    needed = name.replace("_", "-")
    bad = {cause.label: cause for cause in unmet(drive, description.inputs, needed)}
    items = []
    for item in description.inputs:
        variable = _variable(drive, item)
        if variable is None:
            continue
        cause = bad.get(variable.label)
        reason = f"{cause.text}: set it first" if cause else None
        items.append(Precondition(f"value:{item}", f"{variable.label} is set", cause is None, reason))
    return items


def _state(drive: Drive) -> tuple[State | None, int]:
    statusword = int(drive.read("statusword").raw)
    return decode_state(statusword), statusword


def _not_running(drive: Drive, name: str) -> Precondition:
    _, statusword = _state(drive)
    busy = bool(statusword & BUSY)
    reason = (
        "a procedure (or a flash file transfer) is running (status word bit 15 'busy'): wait for it or abort it; "
        "the drive answers a second start with 'cannot execute'"
    )
    return Precondition("not_running", "No procedure running", not busy, reason if busy else None)


def _disabled(drive: Drive, name: str) -> Precondition:
    state, _ = _state(drive)
    ok = state in _DISABLED
    reason = (
        f"the drive is in {state.value if state else 'an unknown state'}: disable it first (the procedure runs with "
        "the power stage off; started while enabled the drive answers 'cannot execute')"
    )
    return Precondition("disabled", "Drive disabled", ok, None if ok else reason)


def _disabled_or_standstill(drive: Drive, name: str) -> Precondition:
    state, _ = _state(drive)
    label = "Drive disabled, or enabled at standstill"
    if state in _DISABLED:
        return Precondition("disabled_or_standstill", label, True)
    if state is not State.OPERATION_ENABLED:
        reason = (
            f"the drive is in {state.value if state else 'an unknown state'}: disable it or enable it at standstill"
        )
        return Precondition("disabled_or_standstill", label, False, reason)
    speed = abs(speed_rad_s(drive, float(drive.read("velocity_actual").raw)))
    ok = speed < STANDSTILL_RAD_S
    reason = (
        f"the axis is moving ({speed * 30 / math.pi:.1f} rpm): auto-tuning enabled runs only at standstill "
        "(the manual: 'if the axis is moving, the procedure is not accepted')"
    )
    return Precondition("disabled_or_standstill", label, ok, None if ok else reason)


def _no_fault(drive: Drive, name: str) -> Precondition:
    _, statusword = _state(drive)
    if not statusword & 0x08:
        return Precondition("no_fault", "No fault", True)
    report = fault_report(drive)
    names = ", ".join(fault.name for fault in report.faults) or report.error_text or "fault"
    return Precondition("no_fault", "No fault", False, f"the drive is in fault ({names}): reset the fault first")


def _no_limit_switch(drive: Drive, name: str) -> Precondition | None:
    if not _has(drive, "digital_inputs"):
        return None
    inputs = int(drive.read("digital_inputs").raw)
    active = [side for bit, side in ((0, "negative"), (1, "positive")) if inputs >> bit & 1]
    label = "No limit switch active"
    if not active:
        return Precondition("no_limit_switch", label, True)
    reason = (
        f"the {' and '.join(active)} limit switch is active: move the axis off it (an active limit switch stops the "
        "procedure with 'procedure error')"
    )
    return Precondition("no_limit_switch", label, False, reason)


def _dc_bus(drive: Drive, name: str) -> Precondition | None:
    if not _has(drive, "dc_bus_voltage"):
        return None
    voltage = float(drive.read("dc_bus_voltage").physical)
    minimum = float(drive.read("dc_bus_minimum").physical) if _has(drive, "dc_bus_minimum") else 0.0
    ok = voltage > max(minimum, 0.0)
    reason = (
        f"the DC bus is at {voltage:g} V (the undervoltage threshold is {minimum:g} V): switch the power supply on "
        "(the procedure drives current through the motor)"
    )
    return Precondition("dc_bus", "DC bus present", ok, None if ok else reason)


def _brake_released(drive: Drive, name: str) -> Precondition | None:
    if not _has(drive, "digital_outputs"):
        return None
    state, _ = _state(drive)
    manual = _has(drive, "digital_output_mask") and int(drive.read("digital_output_mask").raw) & 1
    applied = int(drive.read("digital_outputs").raw) & 1
    ok = not applied if manual else state is State.OPERATION_ENABLED
    reason = (
        "the holding brake is applied (automatic brake control keeps it on while the drive is disabled) and "
        "auto-tuning does not control the brake: release it by manual brake control (digital output bitmask bit 0 "
        "= 1, motor brake output bit 0 = 0; a motor without a brake needs the same), or run enabled at standstill"
    )
    return Precondition("brake_released", "Holding brake released", bool(ok), None if ok else reason)


def _has(drive: Drive, name: str) -> bool:
    return _variable(drive, name) is not None


def _variable(drive: Drive, name: str) -> Variable | None:
    if not drive.profile.has(name) or drive.dictionary is None:
        return None
    return drive.dictionary.get(*drive.profile.address(name))


CHECKS: dict[str, Check] = {
    "not_running": _not_running,
    "disabled": _disabled,
    "disabled_or_standstill": _disabled_or_standstill,
    "no_fault": _no_fault,
    "no_limit_switch": _no_limit_switch,
    "dc_bus": _dc_bus,
    "brake_released": _brake_released,
}
