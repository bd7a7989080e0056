"""CANopen peers for the transport and drive tests: `canopen` slaves on a python-can virtual bus and a fake RS-232
gateway drive.

The slaves come from the independent `canopen` library, so a test of our SDO engine or RS-232 plugin checks it
against someone else's reading of CiA 301, not against our own simulator.
"""

from __future__ import annotations

import contextlib
import itertools
import socket
import threading

import can
import canopen
import pytest

from servostudio.transport.rs232_framing import DRIVE_HEADER, HOST_HEADER, FrameDecoder, encode_frame

_channels = itertools.count()


@pytest.fixture
def virtual_channel() -> str:
    """A fresh python-can virtual channel name per test."""
    return f"servostudio-test-{next(_channels)}"


def make_local_node(node_id: int, network: canopen.Network) -> canopen.LocalNode:
    """A canopen slave with a few objects of every size, including a string for segmented transfers."""
    od = canopen.ObjectDictionary()
    for index, name, data_type, value in [
        (0x1000, "Device type", canopen.objectdictionary.UNSIGNED32, 0x00020192),
        (0x2001, "U8", canopen.objectdictionary.UNSIGNED8, 7),
        (0x2002, "I16", canopen.objectdictionary.INTEGER16, -300),
        (0x2003, "U32", canopen.objectdictionary.UNSIGNED32, 123456),
        (0x2004, "Name", canopen.objectdictionary.VISIBLE_STRING, "axis name longer than four"),
    ]:
        variable = canopen.objectdictionary.ODVariable(name, index, 0)
        variable.data_type = data_type
        variable.access_type = "rw"
        variable.default = value
        od.add_object(variable)
    node = canopen.LocalNode(node_id, od)
    network.add_node(node)
    return node


class FakeGateway:
    """A drive on an RS-232 cable (over TCP) that forwards redirected SDO onto a virtual CAN bus.

    It serves nothing itself: every 0x640+n request goes to the CAN bus as 0x600+n and every 0x580+n response comes
    back as 0x5C0+n (or, with ``quirk``, with the request identifier 0x640+n), which is what the host sees of
    a real gateway drive.
    """

    def __init__(self, channel: str, quirk: bool = False) -> None:
        self.quirk = quirk
        self.bus = can.Bus(interface="virtual", channel=channel, receive_own_messages=False)
        self.server = socket.create_server(("127.0.0.1", 0))
        self.port = self.server.getsockname()[1]
        self.seen_from_host: list[int] = []
        self._client: socket.socket | None = None
        self._stop = threading.Event()
        threading.Thread(target=self._accept, daemon=True).start()
        threading.Thread(target=self._relay_from_can, daemon=True).start()

    @property
    def url(self) -> str:
        return f"socket://127.0.0.1:{self.port}"

    def _accept(self) -> None:
        while not self._stop.is_set():
            try:
                client, _ = self.server.accept()
            except OSError:
                return
            self._client = client
            threading.Thread(target=self._relay_from_host, args=(client,), daemon=True).start()

    def _relay_from_host(self, client: socket.socket) -> None:
        decoder = FrameDecoder(HOST_HEADER)
        while True:
            try:
                chunk = client.recv(256)
            except OSError:
                return
            if not chunk:
                return
            for cob_id, data in decoder.feed(chunk):
                self.seen_from_host.append(cob_id)
                if 0x641 <= cob_id <= 0x67F:
                    self.bus.send(can.Message(arbitration_id=cob_id - 0x40, data=data, is_extended_id=False))

    def _relay_from_can(self) -> None:
        while not self._stop.is_set():
            message = self.bus.recv(0.05)
            client = self._client
            if message is None or client is None or not 0x581 <= message.arbitration_id <= 0x5BF:
                continue
            cob_id = message.arbitration_id + (0xC0 if self.quirk else 0x40)
            with contextlib.suppress(OSError):  # the host went away; the next accept brings a new client
                client.sendall(encode_frame(DRIVE_HEADER, cob_id, bytes(message.data)))

    def cut(self) -> None:
        """Drop the host connection, as when the cable is pulled."""
        if self._client is not None:
            self._client.shutdown(socket.SHUT_RDWR)
            self._client.close()
            self._client = None

    def close(self) -> None:
        self._stop.set()
        self.cut()
        self.server.close()
        self.bus.shutdown()


@pytest.fixture
def slaves(virtual_channel):
    """Nodes 1 and 5 as canopen LocalNodes on a virtual bus."""
    network = canopen.Network()
    network.NOTIFIER_CYCLE = 0.05  # quick teardown
    network.connect(interface="virtual", channel=virtual_channel, receive_own_messages=False)
    nodes = {node_id: make_local_node(node_id, network) for node_id in (1, 5)}
    yield nodes
    network.disconnect()


@pytest.fixture
def gateway(virtual_channel):
    """Factory of fake RS-232 gateway drives on the test's virtual bus; closed after the test."""
    made: list[FakeGateway] = []

    def make(quirk: bool = False) -> FakeGateway:
        made.append(FakeGateway(virtual_channel, quirk=quirk))
        return made[-1]

    yield make
    for item in made:
        item.close()
