"""The block upload codec (drive/sdo_block.py): the frame parsers as properties, and the client's state machine fed
with the frames a server sends, including lost segments and a wrong CRC."""

from __future__ import annotations

import contextlib
import struct

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from servostudio.drive.sdo_block import (
    ABORT_CRC,
    BlockProtocolError,
    BlockUpload,
    Phase,
    ack_request,
    crc16,
    initiate_request,
    parse_end,
    parse_initiate,
    parse_segment,
)

MUX = struct.pack("<HB", 0x5801, 0)
frames = st.binary(min_size=0, max_size=12)


def bitwise_crc(data: bytes) -> int:
    """CRC-16/XMODEM bit by bit, as CiA 301 describes it (an independent reading of the polynomial)."""
    crc = 0
    for byte in data:
        crc ^= byte << 8
        for _ in range(8):
            crc = ((crc << 1) ^ 0x1021) & 0xFFFF if crc & 0x8000 else (crc << 1) & 0xFFFF
    return crc


def test_crc_check_value():
    assert crc16(b"123456789") == 0x31C3  # the published check value of CRC-16/XMODEM


@given(st.binary(max_size=300))
def test_crc_equals_the_bitwise_definition(data):
    assert crc16(data) == bitwise_crc(data)


@given(frames)
def test_parsers_take_any_frame_without_crashing(frame):
    """Any bytes: a value or the protocol error, never another exception."""
    assert parse_initiate(frame, MUX) is None or len(frame) >= 8
    for parse in (parse_segment, parse_end):
        with contextlib.suppress(BlockProtocolError):
            parse(frame)


@given(st.booleans(), st.booleans(), st.integers(0, 2**32 - 1))
def test_initiate_response_round_trip(crc, sized, size):
    command = 0xC0 | (0x04 if crc else 0) | (0x02 if sized else 0)
    response = parse_initiate(bytes([command]) + MUX + struct.pack("<I", size), MUX)
    assert response is not None and response.crc == crc and response.size == (size if sized else None)
    assert parse_initiate(bytes([command]) + struct.pack("<HB", 0x5802, 0) + bytes(4), MUX) is None  # other object


@given(st.integers(1, 127), st.booleans(), st.binary(min_size=7, max_size=7))
def test_segment_round_trip(seqno, last, payload):
    assert parse_segment(bytes([seqno | (0x80 if last else 0)]) + payload) == (seqno, last, payload)


@given(st.integers(0, 7), st.integers(0, 0xFFFF))
def test_end_round_trip(padding, crc):
    assert parse_end(bytes([0xC1 | padding << 2]) + struct.pack("<H", crc) + bytes(5)) == (padding, crc)


@given(st.integers(1, 127), st.integers(0, 255), st.booleans())
def test_requests_are_what_cia301_spells(block_size, threshold, crc):
    frame = initiate_request(MUX, block_size, threshold, crc)
    assert frame == bytes([0xA4 if crc else 0xA0]) + MUX + bytes([block_size, threshold, 0, 0])
    assert ack_request(block_size, 5) == bytes([0xA2, block_size, 5, 0, 0, 0, 0, 0])


@pytest.mark.parametrize("size", [0, 128, 200])
def test_initiate_refuses_a_block_size_outside_1_to_127(size):
    with pytest.raises(ValueError, match="block size"):
        initiate_request(MUX, size)


def server_frames(data: bytes, block_size: int, lose: set[int] = frozenset(), crc: int | None = None):
    """What a CiA 301 server sends for ``data``, block after block; ``lose`` drops the frames of those numbers
    (counted over every segment sent, 0-based) unless one ends its block (the client would wait for it until its
    timeout). Yields each frame, then None where it waits for the client's ack (sent into it)."""
    position, sent = 0, 0
    while True:
        count = 0
        while count < block_size and position + 7 * count < len(data):
            chunk = data[position + 7 * count : position + 7 * count + 7]
            last = position + 7 * count + len(chunk) >= len(data)
            count += 1
            if sent not in lose or last or count == block_size:
                yield bytes([count | (0x80 if last else 0)]) + chunk.ljust(7, b"\0")
            sent += 1
            if last:
                break
        acked = yield None  # the client's ack frame comes back
        position += 7 * acked[1]
        if position >= len(data):
            padding = (7 - len(data) % 7) % 7
            yield bytes([0xC1 | padding << 2]) + struct.pack("<H", crc16(data) if crc is None else crc) + bytes(5)
            return


def run_client(data: bytes, block_size: int = 127, lose: set[int] = frozenset(), crc: int | None = None) -> bytes:
    client = BlockUpload(block_size)
    step = client.on_frame(bytes([0xC6]) + MUX + struct.pack("<I", len(data)), MUX)
    assert step.reply == bytes([0xA3]) + bytes(7) and client.phase is Phase.SEGMENTS
    server = server_frames(data, block_size, lose, crc)
    frame, ack = next(server), b""
    while True:
        if frame is None:  # the server waits for the ack the client sent
            frame = server.send(ack)
            continue
        step = client.on_frame(frame, MUX)
        if step.data is not None:
            assert step.reply == bytes([0xA1]) + bytes(7)
            return step.data
        if step.reply is not None:
            ack = step.reply
        frame = next(server)


@settings(deadline=None)  # a 3 KB transfer frame by frame takes longer than the default 200 ms on a busy host
@given(st.binary(min_size=1, max_size=3000), st.integers(1, 127))
def test_the_client_reassembles_any_data_with_any_block_size(data, block_size):
    assert run_client(data, block_size) == data


@settings(deadline=None)
@given(st.binary(min_size=30, max_size=2000), st.integers(2, 40), st.data())
def test_lost_segments_are_sent_again_and_the_data_is_whole(data, block_size, draw):
    lost = draw.draw(st.sets(st.integers(0, (len(data) + 6) // 7), max_size=3))
    assert run_client(data, block_size, lost) == data


def test_a_wrong_crc_is_refused_with_the_crc_abort():
    with pytest.raises(BlockProtocolError) as refused:
        run_client(b"recorded data" * 10, crc=0x1234)
    assert refused.value.code == ABORT_CRC


def test_an_ordinary_upload_response_is_a_protocol_switch():
    step = BlockUpload().on_frame(bytes([0x41]) + MUX + struct.pack("<I", 100), MUX)
    assert step.switched and step.reply is None
