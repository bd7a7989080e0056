"""The fast frame-length computation against a bit-by-bit reference: ISO 11898-1 stuffing and CRC-15 written out
one bit at a time, as the standard describes them."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from servostudio.sim.frame import Frame
from servostudio.sim.timing import count_stuff_bits, crc15, frame_bits, stuffed_section


def reference_crc15(bits: list[int]) -> int:
    crc = 0
    for bit in bits:
        feedback = bit ^ (crc >> 14)
        crc = (crc << 1) & 0x7FFF
        if feedback:
            crc ^= 0x4599
    return crc


def reference_stuffing(bits: list[int]) -> list[int]:
    """The bits as sent: a complement bit after every 5 equal bits, which starts the next run."""
    sent: list[int] = []
    run_value, run_length = -1, 0
    for bit in bits:
        sent.append(bit)
        run_length = run_length + 1 if bit == run_value else 1
        run_value = bit
        if run_length == 5:
            sent.append(1 - bit)
            run_value, run_length = 1 - bit, 1
    return sent


def reference_section(frame: Frame) -> list[int]:
    def bits(value: int, width: int) -> list[int]:
        return [(value >> shift) & 1 for shift in range(width - 1, -1, -1)]

    rtr = int(frame.rtr)
    section = [0]
    if frame.extended:
        section += [*bits(frame.can_id >> 18, 11), 1, 1, *bits(frame.can_id & 0x3FFFF, 18), rtr, 0, 0]
    else:
        section += [*bits(frame.can_id, 11), rtr, 0, 0]
    section += bits(frame.dlc, 4)
    if not frame.rtr:
        for byte in frame.data:
            section += bits(byte, 8)
    return section + bits(reference_crc15(section), 15)


@st.composite
def frames(draw) -> Frame:
    extended = draw(st.booleans())
    can_id = draw(st.integers(0, (1 << 29) - 1 if extended else 0x7FF))
    rtr = draw(st.booleans())
    byte = st.sampled_from([0x00, 0xFF, 0x55]) | st.integers(0, 255)  # long equal runs are where stuffing happens
    data = bytes(draw(st.integers(0, 8))) if rtr else bytes(draw(st.lists(byte, max_size=8)))
    return Frame(can_id, data, rtr=rtr, extended=extended)


@settings(max_examples=400)
@given(frames())
def test_frame_bits_equal_the_bit_by_bit_reference(frame):
    section = reference_section(frame)
    assert stuffed_section(frame) == section
    assert frame_bits(frame) == len(reference_stuffing(section)) + 13


@settings(max_examples=400)
@given(st.lists(st.sampled_from([0, 1]) | st.just(0), max_size=120))
def test_stuff_bits_and_crc_of_any_bit_sequence(bits):
    assert count_stuff_bits(bits) == len(reference_stuffing(bits)) - len(bits)
    assert crc15(bits) == reference_crc15(bits)
