"""PZD process data of the TTA-PRO: the control word STW (PZD1 out), the status word ZSW (PZD1 in), and the
big-endian word image of the PZD module (TTA-PRO Profibus Communication Profile, Chapter 2, L415-894).

Status bits 0-6 mean what CiA 402 status bits 0-6 mean, so the enabling stages decode the same way; control bits
4 and up are positioner commands (edge-triggered sequence start, jog, homing, moves), not CiA 402 mode bits.
"""

from __future__ import annotations

import enum
import struct


class ControlBit(enum.IntFlag):
    """STW, position mode (L427-478); speed/torque mode uses bits 0-3, 7 and 10 (L650-672)."""

    ON = 0x0001  # 0 = OFF1: ramp stop and disable
    NO_OFF2 = 0x0002  # 0 = OFF2: disable at once
    NO_OFF3 = 0x0004  # 0 = OFF3: stop at maximum deceleration and disable
    ENABLE_OPERATION = 0x0008  # 0 = operation inhibited: ramp stop, back to Ready
    NO_STOP = 0x0010  # 0 = stop at maximum deceleration
    NO_INTERMEDIATE_STOP = 0x0020  # 0 = intermediate stop with the jog deceleration
    RUN_SEQUENCE = 0x0040  # each edge runs the sequence numbered in HSW bits 0-7
    FAULT_ACKNOWLEDGE = 0x0080
    JOG_PLUS = 0x0100
    JOG_MINUS = 0x0200
    PROFIBUS_CONTROL = 0x0400  # 0 = local mode (RS-232); switch only while disabled
    HOMING = 0x0800  # rising edge
    ABSOLUTE_MOVE = 0x1000  # each edge
    RELATIVE_MOVE = 0x2000  # each edge
    GEARING = 0x4000


class StatusBit(enum.IntFlag):
    """ZSW, position mode (L494-535); speed/torque mode has bits 0-9 and 15 (L684-720)."""

    READY_FOR_ENABLING = 0x0001
    READY = 0x0002
    OPERATION_ENABLED = 0x0004
    FAULT = 0x0008
    NO_OFF2 = 0x0010
    NO_OFF3 = 0x0020
    ENABLING_INHIBITED = 0x0040
    WARNING = 0x0080
    NO_FOLLOWING_ERROR = 0x0100  # also 0 on a limit switch, without a fault
    PROFIBUS_CONTROL = 0x0200
    POSITION_REACHED = 0x0400
    HOME_FOUND = 0x0800
    ACKNOWLEDGE = 0x1000  # toggles with each accepted sequence start or manual move
    MOTOR_STOPPED = 0x2000
    SEQUENCE_RUNNING = 0x4000
    SPEED_REACHED = 0x8000


ENABLING_SEQUENCE = (0x0400, 0x0406, 0x0407, 0x043F)
"""The manual's enabling example in position mode, one word per bus cycle (L783-796)."""
ENABLED_MASK = 0x033F
ENABLED_VALUE = 0x0337
"""After ENABLING_SEQUENCE the status word reads xxxx xx11 xx11 0111b."""


class DriveState(enum.Enum):
    """The enabling stages of the manual's state diagram (L554-604), plus the fault state."""

    NOT_READY = "ENABLE not ready"
    ENABLE_INHIBITED = "ENABLE inhibited"
    READY_FOR_ENABLE = "Ready for ENABLE"
    READY = "Ready"
    OPERATION_ENABLED = "Operation enabled"
    FAULT = "Error"


def drive_state(status_word: int) -> DriveState:
    """The stage a status word reports (bits 0-3 and 6)."""
    if status_word & StatusBit.FAULT:
        return DriveState.FAULT
    if status_word & StatusBit.ENABLING_INHIBITED:
        return DriveState.ENABLE_INHIBITED
    for bit, state in (
        (StatusBit.OPERATION_ENABLED, DriveState.OPERATION_ENABLED),
        (StatusBit.READY, DriveState.READY),
        (StatusBit.READY_FOR_ENABLING, DriveState.READY_FOR_ENABLE),
    ):
        if status_word & bit:
            return state
    return DriveState.NOT_READY


def pack_words(words: list[int] | tuple[int, ...]) -> bytes:
    """PZD words as the module's bytes, each big-endian (Motorola order, like PKW)."""
    return struct.pack(f">{len(words)}H", *(word & 0xFFFF for word in words))


def unpack_words(data: bytes) -> tuple[int, ...]:
    if len(data) % 2:
        raise ValueError(f"a PZD module holds whole words, got {len(data)} bytes")
    return struct.unpack(f">{len(data) // 2}H", data)


def split_double(value: int) -> tuple[int, int]:
    """A 32-bit value over two PZD: the first (e.g. PZD5) carries the most significant word."""
    raw = value & 0xFFFFFFFF
    return raw >> 16, raw & 0xFFFF


def join_double(high: int, low: int, signed: bool = True) -> int:
    raw = (high & 0xFFFF) << 16 | (low & 0xFFFF)
    return raw - (1 << 32) if signed and raw & 0x80000000 else raw
