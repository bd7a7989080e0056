"""How long a frame occupies the bus: exact bit count of a classical CAN frame, stuff bits included.

The stuff bits are counted on the frame's actual bits (SOF through CRC, as ISO 11898-1 stuffs them), not with the
worst-case bound, so two frames with the same length but different payloads may differ by a few bit times. The
fixed-form tail (CRC delimiter, ACK slot and delimiter, 7 EOF bits) and the 3-bit intermission are added unstuffed.

Every SDO frame of a backup is a different frame, so the count runs once per frame: the section is built as one
integer, the CRC is table-driven (a byte at a time), and only runs of 4 or more equal bits are looked at for stuff bits.
"""

from __future__ import annotations

import re
from functools import lru_cache

from servostudio.sim.frame import Frame

_CRC15_POLYNOMIAL = 0x4599
_UNSTUFFED_TAIL_BITS = 1 + 2 + 7 + 3  # CRC delimiter, ACK slot + delimiter, end of frame, intermission
_LONG_RUNS = re.compile("0{4,}|1{4,}")


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


def _stuff_bits_of(text: str) -> int:
    """Stuff bits of a '0'/'1' string: one after every 5 equal bits. The stuff bit (the complement) starts the next
    run, so a run right after a stuff bit needs only 4 bits for its own first stuff bit; shorter runs never matter."""
    stuffed, stuffed_at_end_of = 0, -1
    for run in _LONG_RUNS.finditer(text):
        start, end = run.span()
        first = 4 if start == stuffed_at_end_of else 5  # bits of this run until its first stuff bit
        if end - start < first:
            continue
        extra, remainder = divmod(end - start - first, 5)
        stuffed += 1 + extra
        stuffed_at_end_of = end if remainder == 0 else -1
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
    return _stuff_bits_of("".join(map(str, bits)))


@lru_cache(maxsize=4096)
def frame_bits(frame: Frame) -> int:
    """Bit times the frame occupies the bus, including stuff bits and the interframe space."""
    value, length = _section(frame)
    return length + _stuff_bits_of(format(value, f"0{length}b")) + _UNSTUFFED_TAIL_BITS


def frame_duration(frame: Frame, bitrate: int | None) -> float:
    """Seconds on the wire at `bitrate` bit/s; 0 when the timing model is off (`bitrate` None)."""
    if bitrate is None:
        return 0.0
    return frame_bits(frame) / bitrate
