"""Independent peers over the socketcand endpoint: python-can's `socketcand` interface and the `canopen` library.

The simulation runs in real time on its thread; the frames carry virtual time stamps, so periods are checked
against the virtual clock. Nothing here asserts speed.
"""

from __future__ import annotations

import gc
import itertools
import threading
import time

import canopen
import pytest
from canopen.sdo.exceptions import SdoAbortedError
from tests.support.sim_test_drive import DATA, counting_factory

from servostudio.sim import sdo_abort
from servostudio.sim.network import SimulatedNetwork
from servostudio.sim.socketcand import SocketcandServer

EDS = str(DATA / "testdrive.eds")


@pytest.fixture(scope="module")
def peer(test_dictionary):
    network = SimulatedNetwork(
        "1,2,3", device="testdrive", dictionaries={"testdrive": test_dictionary}, behaviour_factory=counting_factory
    )
    network.start()
    server = SocketcandServer(network, port=0).start()
    host, port = server.address
    client = canopen.Network()
    client.connect(interface="socketcand", host=host, port=port, channel="can0")
    nodes = {}
    for node_id in (1, 2, 3):
        node = canopen.RemoteNode(node_id, EDS)
        node.sdo.RESPONSE_TIMEOUT = 5.0  # the host is shared: generous, speed is not what is tested here
        client.add_node(node)
        nodes[node_id] = node
    yield client, nodes, network
    client.disconnect()
    server.stop()
    network.stop()


def test_wrong_channel_is_refused(peer):
    import can

    _, _, network = peer
    with SocketcandServer(network, port=0) as server:
        host, port = server.address
        with pytest.raises(can.CanError, match="error"):
            can.Bus(interface="socketcand", host=host, port=port, channel="vcan7")


def test_expedited_and_segmented_read_write(peer):
    _, nodes, network = peer
    node = nodes[2]
    assert node.sdo["Identity object"]["Vendor-ID"].raw == 0x6C
    assert node.sdo["COB-ID EMCY"].raw == 0x82
    node.sdo["Profile acceleration"].raw = 123456
    assert node.sdo["Profile acceleration"].raw == 123456
    node.sdo["Axis name"].raw = "a name longer than four bytes"
    assert node.sdo["Axis name"].raw == "a name longer than four bytes"
    assert network.node(2).store.get(0x2004) == "a name longer than four bytes"


@pytest.mark.parametrize(
    ("action", "code"),
    [
        (lambda n: n.sdo.upload(0x1234, 0), sdo_abort.OBJECT_DOES_NOT_EXIST),
        (lambda n: n.sdo.upload(0x1018, 7), sdo_abort.SUBINDEX_DOES_NOT_EXIST),
        (lambda n: n.sdo.download(0x6041, 0, b"\x01\x00"), sdo_abort.READ_ONLY),
        (lambda n: n.sdo.upload(0x2100, 0), sdo_abort.WRITE_ONLY),
        (lambda n: n.sdo.download(0x6083, 0, (2_000_000).to_bytes(4, "little")), sdo_abort.VALUE_TOO_HIGH),
        (lambda n: n.sdo.download(0x6083, 0, bytes(4)), sdo_abort.VALUE_TOO_LOW),
        (lambda n: n.sdo.download(0x6083, 0, b"\x01\x00"), sdo_abort.LENGTH_TOO_LOW),
        (lambda n: n.sdo.download(0x1017, 0, b"\x01\x00\x00\x00\x00"), sdo_abort.LENGTH_TOO_HIGH),
    ],
)
def test_abort_codes_reach_the_canopen_client(peer, action, code):
    _, nodes, _ = peer
    with pytest.raises(SdoAbortedError) as raised:
        action(nodes[1])
    assert raised.value.code == code
    # canopen leaves a half-built stream behind after an aborted segmented download; its finaliser sends a request
    # and waits for the answer. Collect it here, not at a random moment on the simulator's thread.
    del raised
    gc.collect()


def test_block_download_and_block_upload_of_a_domain(peer):
    _, nodes, network = peer
    data = bytes((i * 31 + 7) & 0xFF for i in range(6000))
    with nodes[3].sdo[0x5F32][5].open("wb", size=len(data), block_transfer=True) as stream:
        stream.write(data)
    assert network.node(3).store.get(0x5F32, 5) == data
    with network.lock:
        network.node(3).store.set(0x5800, 0, data[::-1])
    with nodes[3].sdo[0x5800].open("rb", block_transfer=True) as stream:
        assert stream.read() == data[::-1]


def test_nmt_heartbeat_and_emcy(peer):
    client, nodes, _network = peer
    node = nodes[1]
    beats: list[tuple[float, int]] = []
    client.subscribe(0x701, lambda can_id, data, timestamp: beats.append((timestamp, data[0])))
    node.sdo["Producer heartbeat time"].raw = 50
    for state in ("OPERATIONAL", "STOPPED", "PRE-OPERATIONAL"):
        node.nmt.state = state
        node.nmt.wait_for_heartbeat(timeout=5)  # may still report the old state (already on its way)
        node.nmt.wait_for_heartbeat(timeout=5)
        assert node.nmt.state == state
    client.unsubscribe(0x701)
    node.sdo["Producer heartbeat time"].raw = 0
    periods = [later[0] - earlier[0] for earlier, later in itertools.pairwise(beats) if later[1] == earlier[1]]
    assert periods and all(abs(period - 0.05) < 2e-3 for period in periods)

    node.nmt.state = "OPERATIONAL"
    node.sdo["Controlword"].raw = 0x8000
    deadline = time.monotonic() + 5
    while not node.emcy.active and time.monotonic() < deadline:
        time.sleep(0.01)
    [emcy] = node.emcy.active
    assert emcy.code == 0x8611 and emcy.register & 0x01
    assert emcy.data[0] == 35  # Infranor code in byte 3 of the frame
    node.nmt.state = "PRE-OPERATIONAL"


def test_pdos_with_the_canopen_library(peer):
    client, nodes, _network = peer
    node = nodes[2]
    node.tpdo.read()
    node.rpdo.read()
    node.nmt.state = "OPERATIONAL"
    received = threading.Event()
    node.tpdo[3].add_callback(lambda pdo: received.set())
    client.sync.transmit()
    assert received.wait(5)
    assert node.tpdo[3]["Position actual value"].raw > 0
    node.rpdo[2]["Target velocity"].raw = -4321
    node.rpdo[2].transmit()
    assert node.sdo["Target velocity"].raw == -4321
    node.nmt.state = "PRE-OPERATIONAL"
