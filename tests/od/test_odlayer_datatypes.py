"""CiA 301 data types: encode/decode round trips (property-based) and the exact wire layout."""

from __future__ import annotations

import math
import struct

import pytest
from hypothesis import given
from hypothesis import strategies as st

from servostudio.od import DataType, EncodingError, decode, encode

INTEGER_TYPES = [t for t in DataType if t.is_integer or t.is_time]


def values_of(data_type: DataType) -> st.SearchStrategy:
    if data_type.is_time:
        days = st.integers(0, 0xFFFF)
        millis = st.integers(0, (1 << 28) - 1)
        return st.builds(lambda d, m: d << 32 | m, days, millis)
    if data_type.is_integer:
        return st.integers(data_type.min_value, data_type.max_value)
    if data_type is DataType.REAL32:
        return st.floats(width=32, allow_nan=False)
    if data_type is DataType.REAL64:
        return st.floats(allow_nan=False)
    if data_type is DataType.VISIBLE_STRING:
        return st.text(alphabet=st.characters(max_codepoint=0xFF), max_size=40)
    if data_type is DataType.UNICODE_STRING:
        return st.text(alphabet=st.characters(blacklist_categories=("Cs",)), max_size=40)
    return st.binary(max_size=64)


@st.composite
def typed_values(draw: st.DrawFn) -> tuple[DataType, object]:
    data_type = draw(st.sampled_from(list(DataType)))
    return data_type, draw(values_of(data_type))


@given(typed_values())
def test_decode_inverts_encode(pair: tuple[DataType, object]) -> None:
    data_type, value = pair
    raw = encode(data_type, value)
    if data_type.size is not None:
        assert len(raw) == data_type.size
    assert decode(data_type, raw) == value


@given(st.sampled_from([t for t in DataType if t.is_integer and t is not DataType.BOOLEAN]), st.data())
def test_encode_inverts_decode_for_every_byte_pattern(data_type: DataType, data: st.DataObject) -> None:
    raw = data.draw(st.binary(min_size=data_type.size, max_size=data_type.size))
    assert encode(data_type, decode(data_type, raw)) == raw


@given(st.binary(min_size=4, max_size=4))
def test_real32_bit_patterns_survive_including_nan(raw: bytes) -> None:
    value = decode(DataType.REAL32, raw)
    if math.isnan(value):
        assert math.isnan(decode(DataType.REAL32, encode(DataType.REAL32, value)))
    else:
        assert encode(DataType.REAL32, value) == raw


@given(st.sampled_from(INTEGER_TYPES), st.data())
def test_integers_outside_the_range_are_refused(data_type: DataType, data: st.DataObject) -> None:
    too_big = data.draw(st.integers(data_type.max_value + 1, data_type.max_value + 1000))
    too_small = data.draw(st.integers(data_type.min_value - 1000, data_type.min_value - 1))
    for value in (too_big, too_small):
        with pytest.raises(EncodingError, match=data_type.name):
            encode(data_type, value)


def test_wire_layout_is_little_endian_two_complement() -> None:
    assert encode(DataType.INTEGER16, -2) == b"\xfe\xff"
    assert encode(DataType.UNSIGNED32, 0x60400010) == b"\x10\x00\x40\x60"
    assert encode(DataType.INTEGER24, -1) == b"\xff\xff\xff"
    assert encode(DataType.UNSIGNED48, 0x0102_0304_0506) == bytes([6, 5, 4, 3, 2, 1])
    assert encode(DataType.REAL32, 1.0) == struct.pack("<f", 1.0)
    assert encode(DataType.VISIBLE_STRING, "save") == b"save"
    assert decode(DataType.UNSIGNED32, b"save") == 0x65766173  # the 'save' signature
    assert encode(DataType.UNICODE_STRING, "Aé") == b"A\x00\xe9\x00"
    assert encode(DataType.TIME_OF_DAY, 3 << 32 | 1000) == b"\xe8\x03\x00\x00\x03\x00"


def test_type_properties() -> None:
    assert (DataType.INTEGER8.min_value, DataType.INTEGER8.max_value) == (-128, 127)
    assert (DataType.UNSIGNED64.min_value, DataType.UNSIGNED64.max_value) == (0, 2**64 - 1)
    assert DataType.BOOLEAN.bits == 1 and DataType.UNSIGNED24.bits == 24
    assert DataType.DOMAIN.size is None and DataType.VISIBLE_STRING.size is None
    assert DataType.REAL64.is_float and DataType.REAL64.is_signed and not DataType.REAL64.is_integer
    assert DataType.UNICODE_STRING.is_text and DataType.OCTET_STRING.is_binary


@pytest.mark.parametrize(
    ("data_type", "value"),
    [
        (DataType.UNSIGNED8, 1.5),
        (DataType.UNSIGNED8, "1"),
        (DataType.REAL32, "1.0"),
        (DataType.REAL32, 1e39),
        (DataType.VISIBLE_STRING, b"abc"),
        (DataType.VISIBLE_STRING, "€"),
        (DataType.DOMAIN, "abc"),
        (DataType.TIME_OF_DAY, 1 << 28),
    ],
)
def test_values_of_the_wrong_kind_are_refused(data_type: DataType, value: object) -> None:
    with pytest.raises(EncodingError):
        encode(data_type, value)


@pytest.mark.parametrize(
    ("data_type", "raw"),
    [
        (DataType.UNSIGNED16, b"\x01"),
        (DataType.REAL64, b"\x00" * 4),
        (DataType.UNICODE_STRING, b"\x41"),
        (DataType.BOOLEAN, b"\x02"),
    ],
)
def test_bad_raw_bytes_are_refused(data_type: DataType, raw: bytes) -> None:
    with pytest.raises(EncodingError):
        decode(data_type, raw)
