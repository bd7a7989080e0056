"""The RS-232 link over its TCP and pseudo-terminal endpoints, spoken byte by byte with the 12-byte framing."""

from __future__ import annotations

import socket
import struct
import time

import pytest
import serial

from servostudio.sim.serial_link import SerialGateway, SerialPty, SerialTcpServer
from servostudio.transport.rs232_framing import DRIVE_HEADER, HOST_HEADER, FrameDecoder, encode_frame

READ_VENDOR = bytes([0x40, 0x18, 0x10, 0x01, 0, 0, 0, 0])
READ_PRODUCT = bytes([0x40, 0x18, 0x10, 0x02, 0, 0, 0, 0])


def wait_for_boot(network) -> None:
    """The drives ignore requests until they have booted (first event of the virtual clock)."""
    deadline = time.monotonic() + 5
    while any(node.state.value == "INITIALISING" for node in network.nodes.values()) and time.monotonic() < deadline:
        time.sleep(0.005)


def read_frames(read, count: int, timeout: float = 5.0) -> list[tuple[int, bytes]]:
    """Decode 'S' frames from `read()` chunks until `count` arrived or the time is up."""
    decoder, frames = FrameDecoder(DRIVE_HEADER), []
    deadline = time.monotonic() + timeout
    while len(frames) < count and time.monotonic() < deadline:
        frames += decoder.feed(read())
    return frames


@pytest.fixture
def line(make_network):
    network = make_network("1,2,3")
    network.start()
    wait_for_boot(network)
    gateway = SerialGateway(network)
    with SerialTcpServer(gateway) as server, socket.create_connection(server.address) as connection:
        connection.settimeout(0.2)
        yield network, gateway, connection
    gateway.close()


def receiver(connection):
    def read() -> bytes:
        try:
            return connection.recv(4096)
        except TimeoutError:
            return b""

    return read


def test_own_node_locally_and_other_nodes_by_redirection(line):
    _network, _, connection = line
    requests = encode_frame(HOST_HEADER, 0x601, READ_VENDOR) + encode_frame(HOST_HEADER, 0x642, READ_PRODUCT)
    for byte in requests:  # byte by byte, as a slow UART delivers them
        connection.sendall(bytes([byte]))
    connection.sendall(encode_frame(HOST_HEADER, 0x643, READ_VENDOR))
    frames = sorted(read_frames(receiver(connection), 3))
    assert [cob_id for cob_id, _ in frames] == [0x581, 0x5C2, 0x5C3]
    assert struct.unpack_from("<I", frames[0][1], 4)[0] == 0x6C
    assert struct.unpack_from("<I", frames[1][1], 4)[0] == 0x1234
    assert frames[2][1][:4] == bytes([0x43, 0x18, 0x10, 0x01])


def test_corrupted_bytes_are_dropped_and_the_link_recovers(line):
    _, _, connection = line
    broken = bytearray(encode_frame(HOST_HEADER, 0x642, READ_VENDOR))
    broken[6] ^= 0x01  # bad XOR: the drive must not answer it
    connection.sendall(b"\x00\xffM\x13garbage" + bytes(broken) + b"SS" + encode_frame(HOST_HEADER, 0x643, READ_PRODUCT))
    frames = read_frames(receiver(connection), 2, timeout=1.0)
    assert [cob_id for cob_id, _ in frames] == [0x5C3]
    assert struct.unpack_from("<I", frames[0][1], 4)[0] == 0x1234


def test_frames_outside_the_redirection_range_are_not_forwarded(line):
    network, _, connection = line
    connection.sendall(encode_frame(HOST_HEADER, 0x602, READ_VENDOR) + encode_frame(HOST_HEADER, 0x000, b"\x01\x00"))
    assert read_frames(receiver(connection), 1, timeout=0.5) == []
    assert network.node(2).state.value == "PRE-OPERATIONAL"


def test_firmware_quirk_returns_the_request_identifier(line):
    _, gateway, connection = line
    gateway.response_id_quirk = True
    connection.sendall(encode_frame(HOST_HEADER, 0x601, READ_VENDOR) + encode_frame(HOST_HEADER, 0x642, READ_VENDOR))
    assert sorted(cob_id for cob_id, _ in read_frames(receiver(connection), 2)) == [0x601, 0x642]


def test_pseudo_terminal_endpoint_with_pyserial(make_network):
    network = make_network("4,5")
    network.start()
    wait_for_boot(network)
    gateway = SerialGateway(network)
    with SerialPty(gateway) as pty, serial.Serial(pty.path, 19200, timeout=0.2) as port:
        port.write(encode_frame(HOST_HEADER, 0x645, READ_PRODUCT))
        [(cob_id, data)] = read_frames(lambda: port.read(64), 1)
    gateway.close()
    assert cob_id == 0x5C5 and struct.unpack_from("<I", data, 4)[0] == 0x1234
