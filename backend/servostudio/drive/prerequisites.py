"""Values a procedure or a move needs from the drive, and the ones that stop it: a value of 0, or one outside its
object's range.

A drive reports only *that* something failed ('atun' ends in fault 64 "Procedure error"; a profile velocity move with
acceleration 0 never starts, without any fault).  The objects each one needs are the device profile's to name
(``procedure_inputs``, ``mode_limits``, by semantic name); reading them names the cause the tool can see.
"""

from __future__ import annotations

from concurrent.futures import Future
from dataclasses import dataclass

from servostudio.drive.access import Drive
from servostudio.drive.cia402 import State, decode_state
from servostudio.drive.sdo import SdoError, settle
from servostudio.errors import InvalidInput
from servostudio.od import Variable

#: read-back status of a signature procedure that stopped on an error (0 never run … 4 stopped on error, 5 done)
PROCEDURE_FAILED = 4


class MoveBlocked(InvalidInput):
    """The axis would be enabled but cannot move: a limit of its mode is 0; nothing was written."""


@dataclass(frozen=True)
class Unmet:
    """One object whose value stops a procedure or a move."""

    label: str
    value: int | float
    problem: str  # "is 0", "is outside 1..24"
    needed_by: str

    @property
    def text(self) -> str:
        return f"{self.label} {self.problem} ({self.needed_by} needs it)"

    def as_dict(self) -> dict[str, object]:
        return {"object": self.label, "value": self.value, "problem": self.problem, "needed_by": self.needed_by}


def unmet(drive: Drive, names: tuple[str, ...], needed_by: str) -> list[Unmet]:
    """The objects among ``names`` (semantic names) that hold 0 or a value outside their range; objects the drive
    does not have or does not answer are left out, since they tell nothing."""
    variables = [variable for name in names if (variable := _known(drive, name)) is not None]
    reads = [(variable, drive.submit_read(variable)) for variable in variables if variable.access.readable]
    causes = []
    for variable, future in reads:
        value = _value(future)
        problem = _problem(variable, value)
        if problem and isinstance(value, (int, float)):
            causes.append(Unmet(variable.label, value, problem, needed_by))
    return causes


def procedure_causes(drive: Drive) -> list[Unmet]:
    """For a procedure fault: the inputs of the procedures that stopped on an error, or of every procedure of the
    profile when none tells (its status cannot be read)."""
    inputs = drive.profile.procedure_inputs
    failed = [trigger for trigger in inputs if _status(drive, trigger) == PROCEDURE_FAILED]
    return [cause for trigger in failed or list(inputs) for cause in unmet(drive, inputs[trigger], _named(trigger))]


def move_blockers(drive: Drive, mode: int) -> list[Unmet]:
    """The limits of operating ``mode`` that are 0 and so keep the axis still (the profile's ``mode_limits``)."""
    limits = drive.profile.mode_limits.get(mode, ())
    return [cause for cause in unmet(drive, limits, f"a move in mode {mode}") if cause.value == 0]


def check_move(drive: Drive) -> None:
    """Refuse to enable an axis that could not move in its present mode, naming the objects that stop it (an
    axis already enabled is left alone: refusing changes nothing there)."""
    if not drive.profile.mode_limits or decode_state(int(drive.read("statusword").raw)) is State.OPERATION_ENABLED:
        return
    shown = drive.read("modes_of_operation_display")
    mode = int(shown.raw)
    blockers = move_blockers(drive, mode)
    if blockers:
        causes = "; ".join(f"{cause.label} is 0" for cause in blockers)
        raise MoveBlocked(
            f"node {drive.node}: the axis could not move in {shown.text} (mode {mode}) once enabled: {causes}; "
            "set them first (nothing was written)"
        )


def _problem(variable: Variable, value: object) -> str:
    """What is wrong with a numeric value a procedure or a move needs ("" when nothing is)."""
    if not isinstance(value, (int, float)) or isinstance(value, bool):
        return ""
    if value == 0:
        return "is 0"
    low, high = variable.minimum, variable.maximum
    if (low is not None and value < low) or (high is not None and value > high):
        return f"is outside {low}..{high}"
    return ""


def _value(future: Future) -> object:
    """The raw value read, None when the drive refused or did not answer (a cause must be seen, not guessed)."""
    try:
        return settle(future).raw
    except SdoError:
        return None


def _status(drive: Drive, trigger: str) -> int | None:
    """A procedure object's read-back status, None when it cannot be read."""
    variable = _known(drive, trigger)
    if variable is None or not variable.access.readable:
        return None
    value = _value(drive.submit_read(variable))
    return value if isinstance(value, int) else None


def _known(drive: Drive, name: str) -> Variable | None:
    """The object a semantic name stands for, when both the profile and this drive's dictionary have it."""
    if not drive.profile.has(name) or drive.dictionary is None:
        return None
    return drive.dictionary.get(*drive.profile.address(name))


def _named(trigger: str) -> str:
    return trigger.replace("_", "-")
