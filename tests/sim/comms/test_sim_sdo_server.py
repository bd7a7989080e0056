"""SDO server over the in-process adapter, byte by byte, with deterministic virtual time."""

from __future__ import annotations

import struct

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from servostudio.sim import sdo_abort
from servostudio.sim.sdo_server import crc16_ccitt


def abort_code(response: bytes) -> int:
    assert response[0] == 0x80, response.hex()
    return struct.unpack_from("<I", response, 4)[0]


@pytest.fixture
def client(make_network, raw_client):
    network = make_network("1,2")
    network.advance(0.001)
    return raw_client(network)


def test_expedited_upload_of_identity_and_node_id_default(client):
    response = client.sdo(1, bytes([0x40, 0x18, 0x10, 0x01]))
    assert response == bytes([0x43, 0x18, 0x10, 0x01, 0x6C, 0, 0, 0])
    response = client.sdo(2, bytes([0x40, 0x14, 0x10, 0x00]))
    assert response[0] == 0x43 and struct.unpack_from("<I", response, 4)[0] == 0x82


def test_expedited_download_is_stored_and_read_back(client):
    assert client.sdo(1, bytes([0x23, 0x83, 0x60, 0]) + struct.pack("<I", 5000))[0] == 0x60
    assert client.network.node(1).store.get(0x6083) == 5000
    assert client.sdo(1, bytes([0x40, 0x83, 0x60, 0]))[4:8] == struct.pack("<I", 5000)


def test_segmented_download_and_upload_of_a_string(client):
    text = b"segmented axis name"
    assert client.sdo(1, bytes([0x21, 0x04, 0x20, 0]) + struct.pack("<I", len(text)))[0] == 0x60
    toggle = 0
    for start in range(0, len(text), 7):
        chunk = text[start : start + 7]
        last = start + 7 >= len(text)
        command = toggle | ((7 - len(chunk)) << 1) | (1 if last else 0)
        assert client.sdo(1, bytes([command]) + chunk) == bytes([0x20 | toggle]).ljust(8, b"\0")
        toggle ^= 0x10
    assert client.network.node(1).store.get(0x2004) == text.decode()

    initiate = client.sdo(1, bytes([0x40, 0x04, 0x20, 0]))
    assert initiate[0] == 0x41 and struct.unpack_from("<I", initiate, 4)[0] == len(text)
    received, toggle = b"", 0
    while True:
        segment = client.sdo(1, bytes([0x60 | toggle]))
        assert segment[0] & 0x10 == toggle
        received += segment[1 : 8 - ((segment[0] >> 1) & 7)]
        toggle ^= 0x10
        if segment[0] & 1:
            break
    assert received == text


@pytest.mark.parametrize(
    ("request_bytes", "code"),
    [
        (bytes([0x40, 0x34, 0x12, 0]), sdo_abort.OBJECT_DOES_NOT_EXIST),
        (bytes([0x40, 0x18, 0x10, 9]), sdo_abort.SUBINDEX_DOES_NOT_EXIST),
        (bytes([0x23, 0x41, 0x60, 0, 1, 0, 0, 0]), sdo_abort.READ_ONLY),  # status word
        (bytes([0x23, 0x01, 0x21, 0, 1, 0, 0, 0]), sdo_abort.READ_ONLY),  # const firmware version
        (bytes([0x40, 0x00, 0x21, 0]), sdo_abort.WRITE_ONLY),  # password
        (bytes([0x23, 0x06, 0x10, 0]) + struct.pack("<I", 150001), sdo_abort.VALUE_TOO_HIGH),
        (bytes([0x23, 0x83, 0x60, 0, 0, 0, 0, 0]), sdo_abort.VALUE_TOO_LOW),
        (bytes([0x2B, 0x83, 0x60, 0, 1, 0, 0, 0]), sdo_abort.LENGTH_TOO_LOW),  # 2 bytes into a U32
        (bytes([0x21, 0x17, 0x10, 0, 4, 0, 0, 0]), sdo_abort.LENGTH_TOO_HIGH),  # 4 bytes into a U16
        (bytes([0x60, 0, 0, 0]), sdo_abort.INVALID_COMMAND),  # segment without a transfer
        (bytes([0xE0, 0, 0, 0]), sdo_abort.INVALID_COMMAND),  # unknown specifier 7
        (bytes([0xA4, 0x18, 0x10, 1, 0, 0, 0, 0]), sdo_abort.INVALID_BLOCK_SIZE),
    ],
)
def test_abort_codes(client, request_bytes, code):
    response = client.sdo(1, request_bytes)
    assert abort_code(response) == code


def test_toggle_bit_error_aborts_the_transfer(client):
    client.sdo(1, bytes([0x21, 0x04, 0x20, 0, 14, 0, 0, 0]))
    assert client.sdo(1, bytes([0x00]) + b"abcdefg")[0] == 0x20
    assert abort_code(client.sdo(1, bytes([0x00]) + b"hijklmn")) == sdo_abort.TOGGLE_BIT_NOT_ALTERNATED
    assert client.network.node(1).store.get(0x2004) == "axis"


def test_abandoned_transfer_times_out(client):
    client.sdo(1, bytes([0x40, 0x04, 0x20, 0]))  # string of 4 bytes -> expedited, no transfer left open
    client.sdo(1, bytes([0x21, 0x04, 0x20, 0, 20, 0, 0, 0]))
    late = [m for m in client.collect(1.5) if m.arbitration_id == 0x581]
    assert len(late) == 1 and abort_code(bytes(late[0].data)) == sdo_abort.SDO_TIMEOUT


def test_second_channel_answers_on_0x5c0_plus_node(client):
    response = client.sdo(2, bytes([0x40, 0x18, 0x10, 2]), request_base=0x640, response_base=0x5C0)
    assert struct.unpack_from("<I", response, 4)[0] == 0x1234


def block_download(client, node_id, index, sub, data, lose_seqno=None):
    """Raw CiA 301 block download; optionally drops one segment of the first block once."""
    response = client.sdo(node_id, bytes([0xC6]) + struct.pack("<HBI", index, sub, len(data)))
    assert response[0] == 0xA4
    block_size = response[4]
    segments = [data[i : i + 7] for i in range(0, len(data), 7)]
    position, dropped = 0, False
    while position < len(segments):
        block = segments[position : position + block_size]
        for seqno, chunk in enumerate(block, start=1):
            last = position + seqno == len(segments)
            if seqno == lose_seqno and not dropped:
                dropped = True
                continue
            client.send(0x600 + node_id, bytes([seqno | (0x80 if last else 0)]) + chunk.ljust(7, b"\0"))
        acks = [m for m in client.collect(0.05) if m.arbitration_id == 0x580 + node_id]
        assert len(acks) == 1 and acks[0].data[0] == 0xA2
        position += acks[0].data[1]
        block_size = acks[0].data[2]
    unused = (7 - len(data) % 7) % 7
    return client.sdo(node_id, bytes([0xC1 | (unused << 2)]) + struct.pack("<H", crc16_ccitt(data)))


def test_block_download_with_a_lost_segment_is_repaired_by_retransmission(client):
    data = bytes((i * 7) & 0xFF for i in range(5000))
    assert block_download(client, 1, 0x5F32, 5, data, lose_seqno=40)[0] == 0xA1
    assert client.network.node(1).store.get(0x5F32, 5) == data


def test_block_download_with_a_wrong_crc_is_refused(client):
    client.sdo(1, bytes([0xC6]) + struct.pack("<HBI", 0x5F32, 5, 10))
    client.send(0x601, bytes([0x01]) + b"0123456")
    client.send(0x601, bytes([0x82]) + b"789\0\0\0\0")
    client.collect(0.05)
    response = client.sdo(1, bytes([0xC1 | (4 << 2)]) + struct.pack("<H", crc16_ccitt(b"0123456789") ^ 1))
    assert abort_code(response) == sdo_abort.CRC_ERROR
    assert client.network.node(1).store.get(0x5F32, 5) == b""


def test_block_upload_with_retransmission_and_crc(client):
    data = bytes(range(256)) * 17 + b"tail"
    client.network.node(1).store.set(0x5800, 0, data)
    response = client.sdo(1, bytes([0xA4, 0x00, 0x58, 0, 100, 0]))
    assert response[0] == 0xC6 and struct.unpack_from("<I", response, 4)[0] == len(data)
    client.send(0x601, bytes([0xA3]).ljust(8, b"\0"))
    received, retransmitted = b"", False
    while True:
        segments = [bytes(m.data) for m in client.collect(0.05) if m.arbitration_id == 0x581]
        if not retransmitted:  # pretend segment 10 of the first block was lost
            retransmitted, segments = True, segments[:9]
        for segment in segments:
            received += segment[1:]
        client.send(0x601, bytes([0xA2, len(segments), 100]).ljust(8, b"\0"))
        if segments and segments[-1][0] & 0x80:
            break
    end = [bytes(m.data) for m in client.collect(0.05) if m.arbitration_id == 0x581]
    assert len(end) == 1 and end[0][0] & 0xE3 == 0xC1
    received = received[: len(received) - ((end[0][0] >> 2) & 7)]
    assert received == data
    assert struct.unpack_from("<H", end[0], 1)[0] == crc16_ccitt(data)
    client.send(0x601, bytes([0xA1]).ljust(8, b"\0"))
    assert client.collect(0.05) == []


def test_block_upload_below_the_switch_threshold_falls_back_to_expedited(client):
    response = client.sdo(1, bytes([0xA4, 0x18, 0x10, 1, 127, 8]))
    assert response == bytes([0x43, 0x18, 0x10, 0x01, 0x6C, 0, 0, 0])


@settings(max_examples=60, deadline=None)
@given(st.binary(max_size=64))
def test_crc16_matches_the_canopen_library(data):
    from canopen.sdo.client import SdoClient

    reference = SdoClient.crc_cls()
    reference.process(data)
    assert crc16_ccitt(data) == reference.final()


@settings(max_examples=40, deadline=None)
@given(st.lists(st.binary(min_size=0, max_size=8), min_size=1, max_size=12))
def test_arbitrary_requests_get_well_formed_answers(test_dictionary, requests):
    from tests.support.sim_test_drive import RawClient, counting_factory

    from servostudio.sim.network import SimulatedNetwork

    network = SimulatedNetwork(
        "1", device="testdrive", dictionaries={"testdrive": test_dictionary}, behaviour_factory=counting_factory
    )
    client = RawClient(network)
    try:
        client.collect(0.001)
        for request in requests:
            client.send(0x601, request)
            for response in client.collect(0.005):
                assert response.arbitration_id in (0x581, 0x81) and len(response.data) == 8
                if response.arbitration_id == 0x581 and response.data[0] == 0x80:
                    assert struct.unpack_from("<I", bytes(response.data), 4)[0] >> 24 in (0x05, 0x06, 0x08)
        assert network.node(1).store.get(0x1018, 1) == 0x6C  # read-only identity untouched
    finally:
        client.close()
