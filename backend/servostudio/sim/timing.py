"""How long a frame occupies the bus: exact bit count of a classical CAN frame, stuff bits included.

The stuff bits are counted on the frame's actual bits (SOF through CRC, as ISO 11898-1 stuffs them), not with the
worst-case bound, so two frames with the same length but different payloads may differ by a few bit times. The
fixed-form tail (CRC delimiter, ACK slot and delimiter, 7 EOF bits) and the 3-bit intermission are added unstuffed.
"""

from __future__ import annotations

from functools import lru_cache

from servostudio.sim.frame import Frame

_CRC15_POLYNOMIAL = 0x4599
_UNSTUFFED_TAIL_BITS = 1 + 2 + 7 + 3  # CRC delimiter, ACK slot + delimiter, end of frame, intermission


def _bits(value: int, width: int) -> list[int]:
    return [(value >> shift) & 1 for shift in range(width - 1, -1, -1)]


def crc15(bits: list[int]) -> int:
    """CAN CRC-15 (polynomial 0x4599) over a bit sequence."""
    crc = 0
    for bit in bits:
        feedback = bit ^ (crc >> 14)
        crc = (crc << 1) & 0x7FFF
        if feedback:
            crc ^= _CRC15_POLYNOMIAL
    return crc


def stuffed_section(frame: Frame) -> list[int]:
    """The bits from start-of-frame to the end of the CRC field, before stuffing."""
    rtr = 1 if frame.rtr else 0
    bits = [0]  # start of frame
    if frame.extended:
        bits += _bits(frame.can_id >> 18, 11) + [1, 1] + _bits(frame.can_id & 0x3FFFF, 18) + [rtr, 0, 0]
    else:
        bits += _bits(frame.can_id, 11) + [rtr, 0, 0]  # RTR, IDE, r0
    bits += _bits(frame.dlc, 4)
    if not frame.rtr:
        for byte in frame.data:
            bits += _bits(byte, 8)
    return bits + _bits(crc15(bits), 15)


def count_stuff_bits(bits: list[int]) -> int:
    """Stuff bits inserted after every run of 5 equal bits (a stuff bit starts the next run)."""
    stuffed = 0
    run_value, run_length = -1, 0
    for bit in bits:
        if bit == run_value:
            run_length += 1
        else:
            run_value, run_length = bit, 1
        if run_length == 5:
            stuffed += 1
            run_value, run_length = 1 - bit, 1
    return stuffed


@lru_cache(maxsize=4096)
def frame_bits(frame: Frame) -> int:
    """Bit times the frame occupies the bus, including stuff bits and the interframe space."""
    section = stuffed_section(frame)
    return len(section) + count_stuff_bits(section) + _UNSTUFFED_TAIL_BITS


def frame_duration(frame: Frame, bitrate: int | None) -> float:
    """Seconds on the wire at `bitrate` bit/s; 0 when the timing model is off (`bitrate` None)."""
    if bitrate is None:
        return 0.0
    return frame_bits(frame) / bitrate
