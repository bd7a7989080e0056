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
