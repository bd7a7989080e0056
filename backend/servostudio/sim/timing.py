"""How long a frame occupies the bus: exact bit count of a classical CAN frame, stuff bits included.

The stuff bits are counted on the frame's actual bits (SOF through CRC, as ISO 11898-1 stuffs them), not with the
worst-case bound, so two frames with the same length but different payloads may differ by a few bit times. The
fixed-form tail (CRC delimiter, ACK slot and delimiter, 7 EOF bits) and the 3-bit intermission are added unstuffed.

Every SDO frame of a backup is a different frame, so the count runs once per frame: the section is built as one
integer, and both the CRC and the stuff bits are table-driven, a byte at a time. Stuffing is a small state machine
(the last bit and how many equal bits end the stream, the stuff bit starting the next run), so a table gives, for
each state and byte, the state after the byte and the stuff bits it needs.
"""

from __future__ import annotations

from functools import lru_cache

from servostudio.sim.frame import Frame

_CRC15_POLYNOMIAL = 0x4599
_UNSTUFFED_TAIL_BITS = 1 + 2 + 7 + 3  # CRC delimiter, ACK slot + delimiter, end of frame, intermission


def _crc15_step(crc: int, bit: int) -> int:
    feedback = bit ^ (crc >> 14)
    crc = (crc << 1) & 0x7FFF
    return crc ^ _CRC15_POLYNOMIAL if feedback else crc


def _byte_table() -> tuple[int, ...]:
    """CRC-15 register after shifting in one byte, for every register top byte XOR data byte."""
    table = []
    for byte in range(256):
        crc = byte << 7
        for _ in range(8):
            crc = _crc15_step(crc, 0)
        table.append(crc)
    return tuple(table)


_CRC15_TABLE = _byte_table()


def _crc15_of(value: int, length: int) -> int:
    """CAN CRC-15 of the `length` bits of `value`, most significant bit first."""
    crc = 0
    lead = length % 8
    for shift in range(length - 1, length - 1 - lead, -1):
        crc = _crc15_step(crc, (value >> shift) & 1)
    for shift in range(length - lead - 8, -1, -8):
        crc = ((crc << 8) & 0x7FFF) ^ _CRC15_TABLE[((crc >> 7) ^ (value >> shift)) & 0xFF]
    return crc


def _section(frame: Frame) -> tuple[int, int]:
    """(bits as an integer, bit count) from start-of-frame to the end of the CRC field, before stuffing."""
    rtr = 1 if frame.rtr else 0
    if frame.extended:  # SOF, base ID, SRR, IDE, extension, RTR, r1, r0
        value = ((frame.can_id >> 18) << 2 | 0b11) << 18 | (frame.can_id & 0x3FFFF)
        value, length = value << 3 | rtr << 2, 1 + 11 + 2 + 18 + 3
    else:  # SOF, ID, RTR, IDE, r0
        value, length = (frame.can_id << 1 | rtr) << 2, 1 + 11 + 3
    value, length = value << 4 | frame.dlc, length + 4
    if not frame.rtr and frame.data:
        value, length = value << 8 * len(frame.data) | int.from_bytes(frame.data, "big"), length + 8 * len(frame.data)
    return value << 15 | _crc15_of(value, length), length + 15


_NO_BIT_YET = 8
"""Stuffing state before the first bit; the others are `last bit * 4 + (equal bits ending the stream - 1)`."""


def _stuff_step(state: int, bit: int) -> tuple[int, int]:
    """(next state, stuff bits inserted) after one bit: a stuff bit follows 5 equal bits and starts the next run."""
    if state != _NO_BIT_YET and state >> 2 == bit:
        run = (state & 3) + 2
        if run == 5:
            return (bit ^ 1) << 2, 1
        return bit << 2 | (run - 1), 0
    return bit << 2, 0


def _stuff_table() -> tuple[tuple[int, ...], ...]:
    """For every state and byte: next state << 8 | stuff bits inserted (most significant bit first)."""
    table = []
    for state in range(_NO_BIT_YET + 1):
        row = []
        for byte in range(256):
            current, stuffed = state, 0
            for shift in range(7, -1, -1):
                current, extra = _stuff_step(current, (byte >> shift) & 1)
                stuffed += extra
            row.append(current << 8 | stuffed)
        table.append(tuple(row))
    return tuple(table)


_STUFF_TABLE = _stuff_table()


def _stuff_bits_of(value: int, length: int) -> int:
    """Stuff bits of the `length` bits of `value`, most significant bit first."""
    state, stuffed = _NO_BIT_YET, 0
    lead = length % 8
    for shift in range(length - 1, length - 1 - lead, -1):
        state, extra = _stuff_step(state, (value >> shift) & 1)
        stuffed += extra
    table = _STUFF_TABLE
    for byte in (value & ((1 << (length - lead)) - 1)).to_bytes((length - lead) // 8, "big"):
        entry = table[state][byte]
        state, stuffed = entry >> 8, stuffed + (entry & 0xFF)
    return stuffed


def stuffed_section(frame: Frame) -> list[int]:
    """The bits from start-of-frame to the end of the CRC field, before stuffing."""
    value, length = _section(frame)
    return [(value >> shift) & 1 for shift in range(length - 1, -1, -1)]


def crc15(bits: list[int]) -> int:
    """CAN CRC-15 (polynomial 0x4599) over a bit sequence."""
    return _crc15_of(int("".join(map(str, bits)) or "0", 2), len(bits))


def count_stuff_bits(bits: list[int]) -> int:
    """Stuff bits inserted after every run of 5 equal bits (a stuff bit starts the next run)."""
    return _stuff_bits_of(int("".join(map(str, bits)) or "0", 2), len(bits))


@lru_cache(maxsize=4096)
def frame_bits(frame: Frame) -> int:
    """Bit times the frame occupies the bus, including stuff bits and the interframe space."""
    value, length = _section(frame)
    return length + _stuff_bits_of(value, length) + _UNSTUFFED_TAIL_BITS


def frame_duration(frame: Frame, bitrate: int | None) -> float:
    """Seconds on the wire at `bitrate` bit/s; 0 when the timing model is off (`bitrate` None)."""
    if bitrate is None:
        return 0.0
    return frame_bits(frame) / bitrate
