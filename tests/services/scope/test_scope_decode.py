"""The roll's batch decoding (docs/scope.md §8) against the per-sample decoding it replaced: any TPDO layout of the
recordable types and any frames decode to the same columns (`frame_columns`), and any column converts to the same
physical values as `ChannelInfo.physical` of each value (`physical_all`)."""

from __future__ import annotations

import struct

from hypothesis import given
from hypothesis import strategies as st

from servostudio.od.datatypes import DataType
from servostudio.services.scope import ChannelInfo
from servostudio.services.scope.capture import FORMATS
from servostudio.services.scope.stream import frame_columns

TYPES = sorted(FORMATS, key=lambda data_type: data_type.name)


@st.composite
def layouts_and_frames(draw: st.DrawFn) -> tuple[struct.Struct, list[bytes]]:
    """A TPDO's mapping (1 to 8 values of the recordable types, at most 8 bytes) and some of its frames."""
    codes: list[str] = []
    for data_type in draw(st.lists(st.sampled_from(TYPES), min_size=1, max_size=8)):
        if struct.calcsize("<" + "".join(codes) + FORMATS[data_type]) <= 8:
            codes.append(FORMATS[data_type])
    layout = struct.Struct("<" + "".join(codes))
    return layout, draw(st.lists(st.binary(min_size=layout.size, max_size=layout.size), max_size=40))


def per_sample(layout: struct.Struct, frames: list[bytes]) -> list[tuple[int | float, ...]]:
    """The decoding the roll did before: one ``unpack_from`` per frame, the samples transposed into columns."""
    samples = [layout.unpack_from(frame) for frame in frames]
    return [tuple(sample[n] for sample in samples) for n in range(len(layout.unpack(bytes(layout.size))))]


def spelled(columns: list[tuple[int | float, ...]] | list[list[int | float]]) -> list[list[str]]:
    """Values as their repr: a NaN of REAL32 equals itself, and 1 and 1.0 differ."""
    return [[repr(value) for value in column] for column in columns]


@given(layouts_and_frames())
def test_a_batch_decodes_to_the_columns_of_the_per_sample_decoding(case):
    layout, frames = case
    assert spelled(frame_columns(layout, frames)) == spelled(per_sample(layout, frames))


SCALES = st.sampled_from([1.0, 0.1, 0.001, 0.0625, 2.5, 1e-6, 360 / 65536, -0.5])
OFFSETS = st.sampled_from([0.0, -273.15, 0.5, 100.0])


@st.composite
def channels_and_raws(draw: st.DrawFn) -> tuple[ChannelInfo, list[int | float]]:
    data_type = draw(st.sampled_from(TYPES))
    info = ChannelInfo("0x2000,0", "x", "u", data_type.name, draw(SCALES), draw(OFFSETS))
    if data_type is DataType.REAL32:
        raws = st.floats(width=32)
    else:
        low, high = data_type.integer_range
        raws = st.integers(low, high)
    return info, draw(st.lists(raws, max_size=30))


@given(channels_and_raws())
def test_a_column_converts_as_each_of_its_values_does(case):
    info, raws = case
    assert spelled([info.physical_all(raws)]) == spelled([[info.physical(raw) for raw in raws]])
