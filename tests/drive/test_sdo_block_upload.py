"""Block SDO upload in the engine: against the simulated XtrapulsPac (block transfers with CRC), a `canopen` slave
(whose server answers a block request with an ordinary upload: the protocol switch), and a scripted CiA 301 block
server on a virtual bus for what the others never do (refuse blocks, send a wrong CRC, stop in the middle)."""

from __future__ import annotations

import struct
import threading
import time

import can
import canopen
import pytest
from tests.support.canopen_peers import make_local_node

from servostudio.drive.link import BusLink
from servostudio.drive.sdo import SdoEngine, SdoError, SdoLinkError, SdoStopped, SdoTimeoutError
from servostudio.drive.sdo_block import crc16
from servostudio.sim.network import SimulatedNetwork

DATA = bytes((n * 37 + n // 7) & 0xFF for n in range(2000))  # 286 segments: 3 blocks of 127 and a short one


def virtual_link(channel: str) -> BusLink:
    link = BusLink("test", lambda: can.Bus(interface="virtual", channel=channel, receive_own_messages=False))
    assert link.start(wait=2.0)
    return link


class BlockServer:
    """Node 9: a CiA 301 block upload server of ``data`` written from the standard, on its own thread. ``refuse``
    answers block requests with abort 0x05040001 (and serves expedited uploads of 4 bytes); ``crc`` replaces the
    CRC of the end frame; ``stall_after`` stops sending after that many segments."""

    def __init__(self, channel: str, data: bytes, refuse=False, crc=None, stall_after=None) -> None:
        self.data, self.refuse, self.crc, self.stall_after = data, refuse, crc, stall_after
        self.requests: list[bytes] = []
        self.bus = can.Bus(interface="virtual", channel=channel, receive_own_messages=False)
        self._stop = threading.Event()
        self._position = self._block = self._sent = 0
        self._thread = threading.Thread(target=self._serve, daemon=True)
        self._thread.start()

    def _reply(self, data: bytes) -> None:
        self.bus.send(can.Message(arbitration_id=0x589, data=data.ljust(8, b"\0"), is_extended_id=False))

    def _serve(self) -> None:
        while not self._stop.is_set():
            message = self.bus.recv(0.02)
            if message is not None and message.arbitration_id == 0x609:
                self.requests.append(bytes(message.data))
                self._handle(bytes(message.data))

    def _handle(self, request: bytes) -> None:
        command, mux = request[0], request[1:4]
        if command & 0xE3 == 0xA0 and self.refuse:
            self._reply(bytes([0x80]) + mux + struct.pack("<I", 0x05040001))
        elif command & 0xE3 == 0xA0:
            self._position, self._block = 0, request[4]
            self._reply(bytes([0xC6]) + mux + struct.pack("<I", len(self.data)))
        elif command == 0xA3:
            self._send_block()
        elif command == 0xA2:
            self._position += 7 * request[1]
            self._block = request[2]
            if self._position < len(self.data):
                self._send_block()
            else:
                padding = (7 - len(self.data) % 7) % 7
                crc = crc16(self.data) if self.crc is None else self.crc
                self._reply(bytes([0xC1 | padding << 2]) + struct.pack("<H", crc))
        elif command == 0x40:
            self._reply(bytes([0x43]) + mux + self.data[:4])

    def _send_block(self) -> None:
        for seqno in range(1, self._block + 1):
            start = self._position + 7 * (seqno - 1)
            if start >= len(self.data) or (self.stall_after is not None and self._sent >= self.stall_after):
                return
            last = start + 7 >= len(self.data)
            self._sent += 1
            self._reply(bytes([seqno | (0x80 if last else 0)]) + self.data[start : start + 7])
            if last:
                return

    def close(self) -> None:
        self._stop.set()
        self._thread.join()
        self.bus.shutdown()


@pytest.fixture
def peer(virtual_channel):
    made: list[BlockServer] = []
    link = virtual_link(virtual_channel)

    def make(**options) -> tuple[SdoEngine, BlockServer]:
        made.append(BlockServer(virtual_channel, options.pop("data", DATA), **options))
        return SdoEngine(link, timeout=0.3), made[-1]

    yield make
    link.close()
    for server in made:
        server.close()


def test_a_block_upload_reads_every_byte_with_progress_per_block(peer):
    engine, server = peer()
    reports: list[tuple[int, int | None]] = []
    data = engine.upload_block(9, 0x5801, 0, progress=lambda done, total: reports.append((done, total))).result(5)
    assert data == DATA
    assert reports == [(889, 2000), (1778, 2000), (2002, 2000)]  # the last block holds the 2 padding bytes
    # the end response leaves with the answer: the scripted server may record it a moment after the future resolved
    deadline = time.monotonic() + 2.0
    while server.requests[-1][0] != 0xA1 and time.monotonic() < deadline:
        time.sleep(0.01)
    acks = [request for request in server.requests if request[0] == 0xA2]
    assert [ack[1] for ack in acks] == [127, 127, 32] and server.requests[-1][0] == 0xA1  # then the end response
    assert server.requests[0] == bytes([0xA4, 0x01, 0x58, 0x00, 127, 0, 0, 0])  # with CRC, block size 127


def test_the_block_size_asked_is_the_one_used(peer):
    engine, server = peer()
    assert engine.upload_block(9, 0x5801, 0, block_size=16).result(5) == DATA
    acks = [request for request in server.requests if request[0] == 0xA2]
    assert len(acks) == 18 and all(ack[2] == 16 for ack in acks) and server.requests[0][4] == 16


def test_a_wrong_crc_fails_the_upload_and_aborts_it(peer):
    engine, server = peer(crc=0xBEEF)
    with pytest.raises(SdoError, match=r"node 9, object 0x5801,0: block upload: CRC 0x[0-9A-F]{4} of the data"):
        engine.upload_block(9, 0x5801, 0).result(5)
    time.sleep(0.1)
    assert server.requests[-1] == bytes([0x80, 0x01, 0x58, 0x00]) + struct.pack("<I", 0x05040004)


def test_a_node_that_refuses_blocks_is_read_by_segmented_upload_from_then_on(peer):
    engine, server = peer(refuse=True)
    assert engine.upload_block(9, 0x5801, 0).result(5) == DATA[:4]
    assert engine.upload_block(9, 0x5801, 0).result(5) == DATA[:4]
    assert [request[0] for request in server.requests] == [0xA4, 0x40, 0x40]  # asked for a block once


def test_a_stop_between_blocks_aborts_the_transfer(peer):
    engine, server = peer()
    seen: list[int] = []
    future = engine.upload_block(9, 0x5801, 0, progress=lambda done, total: seen.append(done), stop=lambda: bool(seen))
    with pytest.raises(SdoStopped, match="upload stopped by the client"):
        future.result(5)
    time.sleep(0.1)
    assert seen == [889] and server.requests[-1][0] == 0x80  # aborted after the first block, no second ack
    assert engine.upload_block(9, 0x5801, 0).result(5) == DATA  # the channel serves the next transfer


def test_a_server_that_stops_sending_segments_times_out(peer):
    engine, _ = peer(stall_after=200)
    with pytest.raises(SdoTimeoutError, match="no SDO response within 300 ms"):
        engine.upload_block(9, 0x5801, 0).result(5)


def test_a_canopen_server_switches_to_a_segmented_upload(virtual_channel):
    """canopen's SdoServer answers a block request with an ordinary upload response (CiA 301's protocol switch)."""
    network = canopen.Network()
    network.NOTIFIER_CYCLE = 0.05
    network.connect(interface="virtual", channel=virtual_channel, receive_own_messages=False)
    node = make_local_node(3, network)
    domain = canopen.objectdictionary.ODVariable("Buffer", 0x2005, 0)
    domain.data_type, domain.access_type, domain.default = canopen.objectdictionary.DOMAIN, "ro", DATA
    node.object_dictionary.add_object(domain)
    link = virtual_link(virtual_channel)
    try:
        engine = SdoEngine(link, timeout=0.5)
        reports: list[tuple[int, int | None]] = []
        data = engine.upload_block(3, 0x2005, 0, progress=lambda *report: reports.append(report)).result(10)
        assert data == DATA
        assert reports == [(889, 2000), (1778, 2000)]  # the segmented upload reports every 127 segments too
        assert engine.upload_block(3, 0x2004, 0).result(5) == node.sdo[0x2004].raw.encode()
    finally:
        link.close()
        network.disconnect()


def test_the_simulated_recorder_buffer_by_block_equals_its_segmented_upload():
    """A recording of the simulated XtrapulsPac (4 KB), read by block upload and by segmented upload."""
    network = SimulatedNetwork("1")
    network.start()
    link = BusLink("sim", network.open_bus)
    try:
        assert link.start(wait=2.0)
        engine = SdoEngine(link, timeout=1.0)
        settings = [  # two 32-bit channels, 256 records, immediate trigger, arm
            (0x5811, 1, struct.pack("<I", 0x60640020)),
            (0x5811, 2, struct.pack("<I", 0x606C0020)),
            (0x5811, 3, bytes(4)),
            (0x5811, 4, bytes(4)),
            (0x5804, 2, struct.pack("<H", 256)),
            (0x5820, 2, b"\x00"),
            (0x5828, 0, b"\x01"),
        ]
        for index, sub, value in settings:
            engine.download(1, index, sub, value).result(5)
        deadline = time.monotonic() + 10
        while engine.upload(1, 0x5829, 0).result(5) != b"\x04":
            assert time.monotonic() < deadline
            time.sleep(0.02)
        reports: list[tuple[int, int | None]] = []
        block = engine.upload_block(1, 0x5801, 0, progress=lambda *report: reports.append(report)).result(10)
        assert len(block) == 256 * 8 and block == engine.upload(1, 0x5801, 0).result(30)
        assert reports[-1] == (2051, 2048) and len(reports) == 3
    finally:
        link.close()
        network.stop()


def test_a_lost_link_ends_a_block_upload_with_a_link_error(peer):
    engine, _ = peer(stall_after=130)
    future = engine.upload_block(9, 0x5801, 0)
    time.sleep(0.1)
    engine.link.close()
    with pytest.raises(SdoLinkError):
        future.result(5)
