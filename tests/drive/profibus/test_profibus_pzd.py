"""PZD control and status words and the word image (TTA-PRO Profibus Communication Profile, Chapter 2)."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from servostudio.drive.profibus.pzd import (
    ENABLED_MASK,
    ENABLED_VALUE,
    ENABLING_SEQUENCE,
    ControlBit,
    DriveState,
    StatusBit,
    drive_state,
    join_double,
    pack_words,
    split_double,
    unpack_words,
)


def test_the_enabling_example_uses_the_control_bits() -> None:
    on = ControlBit.PROFIBUS_CONTROL | ControlBit.NO_OFF2 | ControlBit.NO_OFF3
    assert (
        ControlBit.PROFIBUS_CONTROL,
        on,
        on | ControlBit.ON,
        on | ControlBit.ON | ControlBit.ENABLE_OPERATION | ControlBit.NO_STOP | ControlBit.NO_INTERMEDIATE_STOP,
    ) == ENABLING_SEQUENCE


def test_the_enabled_status_pattern_is_xxxx_xx11_xx11_0111() -> None:
    pattern = "0000001100110111"
    assert int(pattern, 2) == ENABLED_VALUE
    enabled = ENABLED_VALUE | StatusBit.WARNING | StatusBit.SPEED_REACHED
    assert enabled & ENABLED_MASK == ENABLED_VALUE
    assert drive_state(enabled) is DriveState.OPERATION_ENABLED


def test_the_stages_decode_from_bits_0_to_3_and_6() -> None:
    assert drive_state(0x0040 | 0x0230) is DriveState.ENABLE_INHIBITED
    assert drive_state(0x0031) is DriveState.READY_FOR_ENABLE
    assert drive_state(0x0033) is DriveState.READY
    assert drive_state(0x0008) is DriveState.FAULT
    assert drive_state(0x0000) is DriveState.NOT_READY


@given(st.lists(st.integers(0, 0xFFFF), max_size=6))
def test_words_read_back(words) -> None:
    assert list(unpack_words(pack_words(words))) == words


@given(st.integers(-(2**31), 2**31 - 1))
def test_a_double_word_spans_two_pzd_most_significant_first(value: int) -> None:
    high, low = split_double(value)
    assert pack_words([high, low]) == value.to_bytes(4, "big", signed=True)
    assert join_double(high, low) == value
