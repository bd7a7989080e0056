"""What a batch of writes will make an axis do, judged on the values the drive will receive.

The guard must not be fooled by how a caller spells a value (``"15.0"``, ``"1.5e1"``, ``0x8F``) nor by where the
write comes from (a drive file, a restore, the terminal): it judges :class:`~servostudio.drive.access.PlannedWrite`
s — raw values after the dictionary's conversion — and plays the control words through the CiA 402 state machine
(``drive.cia402.transition``) from the state the drive is in, in the order the drive will apply them.  Which objects
move the axis is the device profile's to say (``motion_objects``, ``moving_procedures``), by semantic name.
"""

from __future__ import annotations

import enum
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace

from servostudio.drive.access import PlannedWrite
from servostudio.drive.cia402 import State, transition
from servostudio.drive.nmt import NmtCommand
from servostudio.drive.profiles import DeviceProfile, signature_value


class Motion(enum.IntEnum):
    """What writes make the axis do, from the harmless to what needs the axis's armed controller."""

    NONE = 0  # no motion object among them
    STOPS = 1  # the axis leaves Operation enabled (disable, quick stop): anyone may stop an axis
    PREPARES = 2  # motion objects while the axis stays disabled: the controller's, when the axis has one
    MOVES = 3  # enables, changes what an enabled axis does, or starts a procedure that turns the motor


@dataclass(frozen=True)
class Verdict:
    """The guard's judgment of a batch: the worst of its writes, why, and whether the axis starts or stops."""

    motion: Motion = Motion.NONE
    reason: str = ""
    enables: bool = False
    stops: bool = False

    def worse(self, other: Verdict) -> Verdict:
        """The batch's verdict so far and one more write: the graver motion and its reason decide."""
        graver = other if other.motion > self.motion else self
        return replace(graver, enables=self.enables or other.enables, stops=self.stops or other.stops)


NO_MOTION = Verdict()


class _Role(enum.Enum):
    CONTROLWORD = "controlword"
    MOTION_OBJECT = "motion object"
    PROCEDURE = "procedure"


@dataclass(frozen=True)
class MotionObjects:
    """A device profile's motion objects by address: what each one is, and for procedures the starting value."""

    roles: Mapping[tuple[int, int], _Role]
    starts: Mapping[tuple[int, int], int]

    @classmethod
    def of(cls, profile: DeviceProfile) -> MotionObjects:
        roles = {profile.address(name): _Role.MOTION_OBJECT for name in profile.motion_objects if profile.has(name)}
        starts = {profile.address(name): signature_value(text) for name, text in profile.moving_procedures.items()}
        roles.update(dict.fromkeys(starts, _Role.PROCEDURE))
        if profile.has("controlword"):
            roles[profile.address("controlword")] = _Role.CONTROLWORD
        return cls(roles, starts)

    def touched_by(self, writes: Sequence[PlannedWrite]) -> bool:
        """Whether any write concerns motion at all (else the drive's state need not be read)."""
        return any(write.key in self.roles for write in writes)


def judge(objects: MotionObjects, state: State | None, writes: Sequence[PlannedWrite]) -> Verdict:
    """What ``writes``, applied in order, make an axis in ``state`` do.  None is a state the status word does not
    tell: every motion write is then judged as moving, and the state stays unknown."""
    verdict = NO_MOTION
    for write in writes:
        step, state = _judge_one(objects, state, write)
        verdict = verdict.worse(step)
    return verdict


def _judge_one(objects: MotionObjects, state: State | None, write: PlannedWrite) -> tuple[Verdict, State | None]:
    role = objects.roles.get(write.key)
    if role is _Role.CONTROLWORD:
        return _controlword(state, write.raw)
    if role is _Role.PROCEDURE:
        return _procedure(objects, write), state
    if role is _Role.MOTION_OBJECT:
        return _motion_object(state, write), state
    return NO_MOTION, state


def _controlword(state: State | None, raw: object) -> tuple[Verdict, State | None]:
    """A control word: the transition it makes the drive take from ``state``."""
    if not isinstance(raw, int):
        return Verdict(Motion.MOVES, f"control word {raw!r} is no integer the guard can judge"), None
    if state is None:
        return Verdict(Motion.MOVES, f"control word 0x{raw:04X} to an axis whose state is unknown", enables=True), None
    after = transition(state, raw)
    shown = f"control word 0x{raw:04X} takes the axis from {state.value} to {after.value}"
    if after is State.OPERATION_ENABLED:
        return Verdict(Motion.MOVES, shown, enables=state is not State.OPERATION_ENABLED), after
    if _POWER.get(after, 0) < _POWER.get(state, 0) or _stop_command(raw):
        return Verdict(Motion.STOPS, shown, stops=state is State.OPERATION_ENABLED), after
    return Verdict(Motion.PREPARES, shown), after


def _stop_command(raw: int) -> bool:
    """Disable voltage (bit 1 clear) or quick stop (bit 2 clear) without a fault reset: from every state it leads
    down the ladder or nowhere, so it is a stop anyone may make — a hold watchdog's quick stop of an axis that is
    already disabled too (CiA 402 Table 27)."""
    return not raw & 0x80 and (not raw & 0x02 or not raw & 0x04)


#: how far up the ladder a state is: a transition to a lower one powers the axis down, a stop anyone may make
_POWER = {
    State.SWITCH_ON_DISABLED: 0,
    State.READY_TO_SWITCH_ON: 1,
    State.SWITCHED_ON: 2,
    State.OPERATION_ENABLED: 3,
    State.QUICK_STOP_ACTIVE: 2,  # stopped, below Operation enabled
}


def _procedure(objects: MotionObjects, write: PlannedWrite) -> Verdict:
    """A procedure trigger: its start signature turns the motor even with the power stage off."""
    if write.raw != objects.starts[write.key]:
        return NO_MOTION
    return Verdict(
        Motion.MOVES, f"0x{write.index:04X},{write.sub} = {write.raw:#x} starts a procedure that turns the motor"
    )


def _motion_object(state: State | None, write: PlannedWrite) -> Verdict:
    """A target, mode or profile value: it moves an enabled axis, and prepares the next motion of a disabled one."""
    label = write.variable.label if write.variable is not None else f"0x{write.index:04X},{write.sub}"
    if state in (State.OPERATION_ENABLED, None):
        return Verdict(Motion.MOVES, f"{label} = {write.raw!r} changes what the enabled axis does")
    return Verdict(Motion.PREPARES, f"{label} = {write.raw!r} sets up the axis's next motion")


#: NMT commands after which the drive acts on other values: OPERATIONAL makes its RPDOs act (the control word and
#: set-points another device sends); a reset reloads its stored parameters (the mode, targets: XtrapulsPac 0x205D)
#: or its communication objects (PDO mappings) — into a running axis if it is enabled
_ACTS_ON_OTHER_VALUES = {
    NmtCommand.START: "its RPDOs (the control word and set-points another device sends) then act on",
    NmtCommand.RESET_NODE: "the drive restarts or reloads its stored parameters (mode, targets) into",
    NmtCommand.RESET_COMMUNICATION: "its PDO mappings return to their power-on values in",
}


def judge_nmt(command: NmtCommand, node: int, state: State | None, nmt_state: str | None) -> Verdict:
    """What an NMT command makes the axis of ``node`` do (``state``: its CiA 402 state, None when unknown), judged
    as a motion object's write is: start and the resets make the drive act on other values — on an enabled axis
    that changes what it does (moving; the worst case of the devices), on a disabled one it sets up its next motion
    (preparing).  Stop and pre-operational end PDO control and start nothing (the drive's abort-connection option,
    0x6007, decides what an enabled axis does: stopping an axis never needs its controller)."""
    name = command.name.lower().replace("_", "-")
    acts = _ACTS_ON_OTHER_VALUES.get(command)
    if acts is None or (command is NmtCommand.START and nmt_state == "OPERATIONAL"):
        return Verdict(Motion.NONE, f"NMT {name} of node {node}")
    if state in (State.OPERATION_ENABLED, None):
        shown = "the enabled axis" if state is not None else "an axis whose state is unknown"
        return Verdict(Motion.MOVES, f"NMT {name} of node {node}: {acts} {shown}")
    return Verdict(Motion.PREPARES, f"NMT {name} of node {node}: {acts} the axis's next motion")
