"""The recorder's record packing (`struct`, for speed) is exactly the CiA 301 encoding `od.encode` defines, so a
peer that decodes the buffer value by value with `od.decode` gets back what was recorded."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st
from tests.support.recorder_peer import decode_records

from servostudio.od.datatypes import DataType, encode
from servostudio.sim.drive.recording import FORMATS, pack_records, record_struct


def values_of(data_type: DataType) -> st.SearchStrategy:
    if data_type is DataType.REAL32:
        return st.floats(width=32, allow_nan=False)
    low, high = data_type.integer_range
    return st.integers(low, high)


@st.composite
def recordings(draw) -> tuple[list[DataType], list[tuple]]:
    types = draw(st.lists(st.sampled_from(sorted(FORMATS)), min_size=1, max_size=4))
    records = draw(st.lists(st.tuples(*[values_of(data_type) for data_type in types]), max_size=40))
    return types, records


@given(recordings())
def test_packed_records_are_the_channels_cia301_encodings_in_channel_order(recording):
    types, records = recording
    layout = record_struct(types)
    packed = pack_records(layout, records)
    assert packed == b"".join(encode(t, value) for record in records for t, value in zip(types, record, strict=True))
    assert layout.size == sum(data_type.fixed_size for data_type in types)
    assert decode_records(packed, types) == records
