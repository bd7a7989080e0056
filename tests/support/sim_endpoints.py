"""Simulated drives for the drive, services, API and CLI tests: one real-time `SimulatedNetwork` per module, reached
over socketcand or the RS-232 link (both endpoints can be cut and brought back), and a helper that commissions a
drive so that a backup holds every object.
"""

from __future__ import annotations

import contextlib
import time

import pytest

from servostudio.services.backup import FileKind, backup_objects

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


def wait_connected(connection, timeout: float = 15.0) -> None:
    """Until the connection's link is back (after the endpoint was cut and restored)."""
    deadline = time.monotonic() + timeout
    while not connection.link.connected:
        assert time.monotonic() < deadline, "the link did not come back"
        time.sleep(0.05)
