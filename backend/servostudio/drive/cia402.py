"""CiA 402 device control: state from the status word, control-word commands, the path to a target state.

State decoding uses the standard masks (XtrapulsPac manual §3.4, status test mask 0x026F without bit 9):
bits 6, 5, 3, 2, 1, 0.  The path to a target state follows the standard transitions, one command per step.
"""

from __future__ import annotations

import enum

from servostudio.errors import InvalidInput


class State(enum.StrEnum):
    NOT_READY_TO_SWITCH_ON = "NOT READY TO SWITCH ON"
    SWITCH_ON_DISABLED = "SWITCH ON DISABLED"
    READY_TO_SWITCH_ON = "READY TO SWITCH ON"
    SWITCHED_ON = "SWITCHED ON"
    OPERATION_ENABLED = "OPERATION ENABLED"
    QUICK_STOP_ACTIVE = "QUICK STOP ACTIVE"
    FAULT_REACTION_ACTIVE = "FAULT REACTION ACTIVE"
    FAULT = "FAULT"

    @classmethod
    def parse(cls, text: str) -> State:
        key = text.strip().upper().replace("-", " ").replace("_", " ")
        aliases = {
            "ENABLED": "OPERATION ENABLED",
            "OPERATION ENABLE": "OPERATION ENABLED",
            "DISABLED": "SWITCH ON DISABLED",
            "READY": "READY TO SWITCH ON",
        }
        key = aliases.get(key, key)
        for state in cls:
            if state.value == key:
                return state
        raise InvalidInput(
            f"unknown CiA 402 state {text!r}; use one of: "
            + ", ".join(state.value.lower().replace(" ", "-") for state in cls)
        )


_DECODING = [  # (mask, value, state), first match wins
    (0x4F, 0x00, State.NOT_READY_TO_SWITCH_ON),
    (0x4F, 0x40, State.SWITCH_ON_DISABLED),
    (0x6F, 0x21, State.READY_TO_SWITCH_ON),
    (0x6F, 0x23, State.SWITCHED_ON),
    (0x6F, 0x27, State.OPERATION_ENABLED),
    (0x6F, 0x07, State.QUICK_STOP_ACTIVE),
    (0x4F, 0x0F, State.FAULT_REACTION_ACTIVE),
    (0x4F, 0x08, State.FAULT),
]


def decode_state(statusword: int) -> State | None:
    for mask, value, state in _DECODING:
        if statusword & mask == value:
            return state
    return None


class Command(enum.IntEnum):
    """Control-word values of the device-control commands (bits 7, 3, 2, 1, 0)."""

    SHUTDOWN = 0x06
    SWITCH_ON = 0x07
    DISABLE_VOLTAGE = 0x00
    QUICK_STOP = 0x02
    DISABLE_OPERATION = 0x07
    ENABLE_OPERATION = 0x0F
    FAULT_RESET = 0x80


_COMMAND_BITS = 0x8F  # bits a command sets; the mode-specific bits 4-6 and bits 8+ are kept


def apply_command(controlword: int, command: Command) -> int:
    """Control word with the command's bits, keeping the mode-specific and manufacturer bits."""
    return (controlword & ~_COMMAND_BITS & 0xFFFF) | int(command)


_NEXT_STEP: dict[tuple[State, State], Command] = {}
_ORDER = [State.SWITCH_ON_DISABLED, State.READY_TO_SWITCH_ON, State.SWITCHED_ON, State.OPERATION_ENABLED]
_UP = {
    State.SWITCH_ON_DISABLED: Command.SHUTDOWN,
    State.READY_TO_SWITCH_ON: Command.SWITCH_ON,
    State.SWITCHED_ON: Command.ENABLE_OPERATION,
}
_DOWN = {
    State.OPERATION_ENABLED: Command.DISABLE_OPERATION,
    State.SWITCHED_ON: Command.SHUTDOWN,
    State.READY_TO_SWITCH_ON: Command.DISABLE_VOLTAGE,
}


def next_command(current: State, target: State) -> Command | None:
    """The command that moves one step from ``current`` towards ``target``; None when already there.

    Reachable targets: the four states of the normal ladder and QUICK STOP ACTIVE (from OPERATION ENABLED).
    A quick stop is only ever a way down: from any state but OPERATION ENABLED the axis is already stopped and no
    command is given (a drive whose quick-stop option code ends in SWITCH ON DISABLED must not be walked back up).
    A fault must be reset first (FAULT_RESET), which leads to SWITCH ON DISABLED.
    """
    if current is target:
        return None
    if target is State.QUICK_STOP_ACTIVE:
        return Command.QUICK_STOP if current is State.OPERATION_ENABLED else None
    if current is State.FAULT:
        return Command.FAULT_RESET
    if current is State.QUICK_STOP_ACTIVE:
        return Command.DISABLE_VOLTAGE
    if target not in _ORDER or current not in _ORDER:
        raise InvalidInput(f"no command leads from {current.value} to {target.value}")
    if _ORDER.index(target) > _ORDER.index(current):
        return _UP[current]
    return _DOWN[current]


FAULT_RESET_BIT = 0x80


def decode_command(controlword: int) -> Command:
    """The device-control command a drive reads in bits 3–0 (CiA 402 table, XtrapulsPac manual §3.2.1.2), checked
    in the standard's order: a cleared bit 1 is Disable voltage whatever the others say, then bit 2, then bit 0.
    Bit 7 (fault reset) is left to :func:`transition`: drives apply the bits 3–0 command with it all the same."""
    if not controlword & 0x02:
        return Command.DISABLE_VOLTAGE
    if not controlword & 0x04:
        return Command.QUICK_STOP
    if not controlword & 0x01:
        return Command.SHUTDOWN
    return Command.ENABLE_OPERATION if controlword & 0x08 else Command.SWITCH_ON


#: (state, command) → the state the drive goes to; a pair not listed leaves the state as it is.  Switch on +
#: Enable operation from READY TO SWITCH ON goes through to OPERATION ENABLED (transitions 3 + 4), and Enable
#: operation leads back from QUICK STOP ACTIVE (transition 16, with quick-stop option codes 5–8).
_TRANSITIONS: dict[tuple[State, Command], State] = {
    (State.SWITCH_ON_DISABLED, Command.SHUTDOWN): State.READY_TO_SWITCH_ON,
    (State.READY_TO_SWITCH_ON, Command.DISABLE_VOLTAGE): State.SWITCH_ON_DISABLED,
    (State.READY_TO_SWITCH_ON, Command.QUICK_STOP): State.SWITCH_ON_DISABLED,
    (State.READY_TO_SWITCH_ON, Command.SWITCH_ON): State.SWITCHED_ON,
    (State.READY_TO_SWITCH_ON, Command.ENABLE_OPERATION): State.OPERATION_ENABLED,
    (State.SWITCHED_ON, Command.DISABLE_VOLTAGE): State.SWITCH_ON_DISABLED,
    (State.SWITCHED_ON, Command.QUICK_STOP): State.SWITCH_ON_DISABLED,
    (State.SWITCHED_ON, Command.SHUTDOWN): State.READY_TO_SWITCH_ON,
    (State.SWITCHED_ON, Command.ENABLE_OPERATION): State.OPERATION_ENABLED,
    (State.OPERATION_ENABLED, Command.DISABLE_VOLTAGE): State.SWITCH_ON_DISABLED,
    (State.OPERATION_ENABLED, Command.QUICK_STOP): State.QUICK_STOP_ACTIVE,
    (State.OPERATION_ENABLED, Command.SHUTDOWN): State.READY_TO_SWITCH_ON,
    (State.OPERATION_ENABLED, Command.SWITCH_ON): State.SWITCHED_ON,
    (State.QUICK_STOP_ACTIVE, Command.DISABLE_VOLTAGE): State.SWITCH_ON_DISABLED,
    (State.QUICK_STOP_ACTIVE, Command.ENABLE_OPERATION): State.OPERATION_ENABLED,
}


def transition(state: State, controlword: int) -> State:
    """The state a drive in ``state`` goes to when it receives ``controlword``.

    The worst case where drives differ, because the motion guard decides on it: bit 7 in FAULT is taken as the
    reset edge (the previous control word is not known), and the bits 3–0 command then applies from SWITCH ON
    DISABLED as the drives do; Enable operation from QUICK STOP ACTIVE is taken as leading back to OPERATION
    ENABLED whatever the quick-stop option code."""
    if state is State.FAULT and controlword & FAULT_RESET_BIT:
        state = State.SWITCH_ON_DISABLED
    return _TRANSITIONS.get((state, decode_command(controlword)), state)
