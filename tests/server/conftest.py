"""Fixtures of the server tests: CANopen slaves on a python-can virtual bus and a fake RS-232 gateway drive."""

from __future__ import annotations

import contextlib
import itertools
import socket
import sys
import threading

import can
import canopen
import pytest

from servostudio.services.backup import FileKind, backup_objects
from servostudio.transport.rs232_framing import DRIVE_HEADER, HOST_HEADER, FrameDecoder, encode_frame

_channels = itertools.count()


@pytest.fixture(autouse=True, scope="module")
def short_switch_interval():
    """The simulated drives, the bus reader and the socket threads share one interpreter here: a short GIL switch
    interval keeps each hand-over (and so every SDO round trip) at a fraction of a millisecond instead of 5 ms.
    Only for these modules; the interpreter's setting is restored afterwards."""
    previous = sys.getswitchinterval()
    sys.setswitchinterval(0.0002)
    yield
    sys.setswitchinterval(previous)


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
            try:
                client.sendall(encode_frame(DRIVE_HEADER, cob_id, bytes(message.data)))
            except OSError:
                pass

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


FAST_SDO_RESPONSE = 0.2e-3  # the functional tests do not need the drive's realistic 1 ms, only its behaviour


@contextlib.contextmanager
def slow_drives(network, response_time: float = 2e-3):
    """Drives that take ``response_time`` per SDO answer, so a long transfer is certainly still running when a test
    cuts the link (≈ 370 objects × 2.2 ms ≈ 0.8 s, while a cut takes effect within about 0.2 s)."""
    servers = [server for node in network.nodes.values() for server in (node.sdo, node.redirected_sdo)]
    for server in servers:
        server.response_time = response_time
    try:
        yield
    finally:
        for server in servers:
            server.response_time = FAST_SDO_RESPONSE


@pytest.fixture
def slow():
    """``with slow(network): …`` — drives answering SDO in 2 ms instead of 0.2 ms for the duration of the block."""
    return slow_drives


@pytest.fixture(scope="module")
def sim_network(tmp_path_factory):
    """Three simulated XtrapulsPac drives (nodes 1, 2, 3) in real time (`SimulatedNetwork.start()`), one per test
    module.

    Tests do not rely on values another test of the module may have changed: each sets or reads back what it
    checks.  (Module scope, not session: the running simulation would otherwise take CPU from every later module.)
    """
    from servostudio.sim.network import SimulatedNetwork

    network = SimulatedNetwork(
        "1,2,3", state_dir=tmp_path_factory.mktemp("sim-flash"), sdo_response_time=FAST_SDO_RESPONSE
    )
    network.start()
    yield network
    network.stop()


class Socketcand:
    """The simulator's socketcand endpoint, which a test can cut and bring back on the same port."""

    def __init__(self, network) -> None:
        from servostudio.sim.socketcand import SocketcandServer

        self._server_type = SocketcandServer
        self.network = network
        self.server = SocketcandServer(network, port=0).start()
        self.port = self.server.address[1]

    @property
    def spec(self) -> str:
        return f"socketcand:127.0.0.1:{self.port}"

    def cut(self) -> None:
        self.server.stop()
        self.server = None

    def restore(self) -> None:
        self.server = self._server_type(self.network, port=self.port).start()

    def close(self) -> None:
        if self.server is not None:
            self.server.stop()


@pytest.fixture(scope="module")
def socketcand(sim_network):
    endpoint = Socketcand(sim_network)
    yield endpoint
    endpoint.close()


@pytest.fixture
def manager():
    from servostudio.services.bus import ConnectionManager

    connections = ConnectionManager()
    yield connections
    connections.close_all()


def _commission(drive) -> None:
    """Give in-range values to saved objects a drive holds outside their range, and a text to empty names.

    A fresh simulated drive holds only in-range values (docs/simulator.md, factory values), so the first part
    changes nothing there; empty names get a text so that a backup holds every object (the object file cannot
    carry an empty text, and a backup leaves such objects out).
    """
    variables = [
        var for kind in (FileKind.DRIVEPAR, FileKind.USER_PAR) for var in backup_objects(drive, kind.save_type)
    ]
    reads = [(var, drive.submit_read(var)) for var in variables]
    for var, future in reads:
        value = future.result().raw
        if isinstance(value, int) and not var.minimum <= value <= var.maximum:
            drive.write(var, var.minimum)
        elif isinstance(value, str) and not value.strip("\0 "):
            drive.write(var, f"node{drive.node}")


@pytest.fixture(scope="session")
def commission():
    return _commission


class SerialEndpoint:
    """The simulator's RS-232 line (raw TCP) on node 1, which a test can cut and bring back on the same port."""

    def __init__(self, network, quirk: bool) -> None:
        from servostudio.sim.serial_link import SerialGateway, SerialTcpServer

        self._server_type = SerialTcpServer
        self.gateway = SerialGateway(network, response_id_quirk=quirk)
        self.server = SerialTcpServer(self.gateway, port=0).start()
        self.port = self.server.address[1]

    @property
    def spec(self) -> str:
        return f"serial:socket://127.0.0.1:{self.port}@115200"

    def cut(self) -> None:
        self.server.stop()
        self.server = None

    def restore(self) -> None:
        self.server = self._server_type(self.gateway, port=self.port).start()

    def close(self) -> None:
        if self.server is not None:
            self.server.stop()
        self.gateway.close()


@pytest.fixture(scope="module")
def serial_line(sim_network):
    """RS-232 line into node 1 with the firmware quirk on (responses carry the request identifier)."""
    endpoint = SerialEndpoint(sim_network, quirk=True)
    yield endpoint
    endpoint.close()


@pytest.fixture(scope="module", params=["socketcand", "serial"])
def endpoint(request, sim_network):
    """The simulated drives reached over socketcand, then over the RS-232 link (same tests, both transports)."""
    made = Socketcand(sim_network) if request.param == "socketcand" else SerialEndpoint(sim_network, quirk=True)
    yield made
    made.close()
