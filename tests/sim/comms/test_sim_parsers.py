"""Property-based tests of the simulator's text parsers: node lists and the socketcand protocol."""

from __future__ import annotations

import can
import pytest
from can.interfaces.socketcand.socketcand import (
    convert_ascii_message_to_can_message,
    convert_can_message_to_ascii_message,
)
from hypothesis import given, settings
from hypothesis import strategies as st

from servostudio.sim.frame import Frame
from servostudio.sim.network import NodeSpec, parse_node_list
from servostudio.sim.socketcand import format_frame, parse_send

devices = st.sampled_from(["xtrapulspac", "cd1k", "encotrive"])
node_specs = st.lists(
    st.tuples(st.integers(1, 127), st.one_of(st.none(), devices)),
    min_size=1,
    max_size=10,
    unique_by=lambda spec: spec[0],
)


@given(node_specs)
def test_node_list_round_trip(specs):
    text = ",".join(f"{node}:{device}" if device else str(node) for node, device in specs)
    assert parse_node_list(text, "cd1k") == [NodeSpec(node, device or "cd1k") for node, device in specs]


@pytest.mark.parametrize(
    ("text", "reason"),
    [
        ("", "empty entry"),
        ("1,,2", "empty entry"),
        ("x", "not a node ID"),
        ("0", "outside 1..127"),
        ("128", "outside 1..127"),
        ("3,3:cd1k", "appears twice"),
    ],
)
def test_bad_node_lists_name_the_reason(text, reason):
    with pytest.raises(ValueError, match=reason):
        parse_node_list(text)


frames = st.builds(
    lambda extended, can_id, data: Frame(can_id & (0x1FFFFFFF if extended else 0x7FF), data, extended=extended),
    st.booleans(),
    st.integers(0, 0x1FFFFFFF),
    st.binary(max_size=8),
)


@given(frames)
def test_what_python_can_sends_is_parsed_back(frame):
    message = can.Message(arbitration_id=frame.can_id, data=frame.data, is_extended_id=frame.extended)
    words = convert_can_message_to_ascii_message(message)[1:-1].split()
    assert words[0] == "send"
    assert parse_send(words[1:]) == frame


@given(frames, st.floats(0, 1e6, allow_nan=False))
def test_what_the_server_sends_is_read_by_python_can(frame, timestamp):
    message = convert_ascii_message_to_can_message(format_frame(frame, timestamp))
    assert (message.arbitration_id, bytes(message.data), message.is_extended_id) == (
        frame.can_id,
        frame.data,
        frame.extended,
    )
    assert message.timestamp == pytest.approx(timestamp, abs=1e-6)


@settings(max_examples=60)
@given(st.lists(st.text(alphabet="0123456789abcdefxyz", max_size=4), max_size=12))
def test_arbitrary_send_arguments_give_a_frame_or_a_value_error(words):
    try:
        frame = parse_send(words)
    except ValueError:
        return
    assert isinstance(frame, Frame) and frame.dlc == int(words[1], 16)
