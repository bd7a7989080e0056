"""The bit patterns of ``--input-bits`` / ``--sim-inputs`` and the inputs route: numbers or 1/0/. MSB first."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from servostudio.errors import InvalidInput
from servostudio.services.sequences import parse_bits


@given(st.text(alphabet="10.", min_size=1, max_size=16), st.integers(0, 0xFFFF))
def test_a_pattern_sets_its_bits_and_keeps_the_dotted_ones(pattern, current):
    value = parse_bits(pattern, 16, current)
    for bit, char in enumerate(reversed(pattern)):
        expected = (current >> bit & 1) if char == "." else int(char)
        assert value >> bit & 1 == expected
    assert value >> len(pattern) == current >> len(pattern)


@given(st.integers(0, 0xFFFF))
def test_a_number_is_taken_as_it_is(number):
    assert parse_bits(hex(number), 16) == number
    if set(str(number)) - set("10"):  # 1s and 0s alone are a pattern
        assert parse_bits(str(number), 16) == number


@pytest.mark.parametrize("text", ["", "12345678901234567", "1x", "0x10000", "-1", "1" * 17])
def test_anything_else_is_refused(text):
    with pytest.raises(InvalidInput):
        parse_bits(text, 16)
