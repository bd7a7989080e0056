"""NMT, boot-up, heartbeat, node guarding, EMCY, SYNC and PDOs on the in-process adapter (virtual time)."""

from __future__ import annotations

import itertools
import struct

import pytest
from tests.support.sim_test_drive import frames_with_id, write

from servostudio.sim import sdo_abort


@pytest.fixture
def client(make_network, raw_client):
    network = make_network("1,2")
    client = raw_client(network)
    client.collect(0.001)
    return client


def test_no_boot_up_by_default_and_boot_up_after_reset_when_0x2010_is_1(client):
    write(client, 1, 0x2010, 0, 1, size=2)
    write(client, 1, 0x1017, 0, 500, size=2)
    client.send(0x000, bytes([0x82, 1]))  # reset communication
    messages = client.collect(0.01)
    assert [bytes(m.data) for m in frames_with_id(messages, 0x701)] == [b"\x00"]
    assert frames_with_id(messages, 0x702) == []
    assert client.network.node(1).store.get(0x1017) == 0  # communication area back to its default
    assert client.network.node(1).store.get(0x2010) == 1  # manufacturer area untouched
    assert client.network.node(1).state.value == "PRE-OPERATIONAL"


def test_heartbeat_period_and_nmt_states(client):
    write(client, 1, 0x1017, 0, 100, size=2)
    beats = frames_with_id(client.collect(0.35), 0x701)
    assert [bytes(b.data) for b in beats] == [b"\x7f"] * 3
    assert [later.timestamp - earlier.timestamp for earlier, later in itertools.pairwise(beats)] == pytest.approx(
        [0.1, 0.1], abs=1e-3
    )
    for command, state in ((0x01, 0x05), (0x02, 0x04), (0x80, 0x7F), (0x01, 0x05)):
        client.send(0x000, bytes([command, 0]))
        beats = frames_with_id(client.collect(0.1), 0x701)
        assert [b.data[0] for b in beats] == [state]


def test_stopped_node_ignores_sdo(client):
    client.send(0x000, bytes([0x02, 2]))
    client.send(0x602, bytes([0x40, 0x00, 0x10, 0, 0, 0, 0, 0]))
    assert frames_with_id(client.collect(0.01), 0x582) == []
    assert client.network.node(1).state.value == "PRE-OPERATIONAL"


def test_node_guarding_toggles_and_life_guarding_stops_the_node(client):
    write(client, 1, 0x100C, 0, 50, size=2)
    write(client, 1, 0x100D, 0, 2, size=1)
    write(client, 1, 0x205E, 0, 2, size=2)
    answers = []
    for _ in range(3):
        client.send(0x701, rtr=True, dlc=1)
        answers += [m.data[0] for m in frames_with_id(client.collect(0.02), 0x701)]
    assert answers == [0x7F, 0xFF, 0x7F]
    client.collect(0.2)  # no guarding request for longer than 50 ms x 2
    assert client.network.node(1).state.value == "STOPPED"


def test_emcy_on_fault_and_on_reset_with_error_register(client):
    client.send(0x000, bytes([0x01, 0]))
    write(client, 1, 0x205F, 0, 2, size=2)
    write(client, 1, 0x6040, 0, 0x8000, size=2)
    [emcy] = frames_with_id(client.collect(0.01), 0x81)
    assert bytes(emcy.data) == struct.pack("<HBB", 0x8611, 0x01, 35) + b"\x01\x02\x00\x00"
    assert client.network.node(1).store.get(0x1003, 1) & 0xFFFF == 0x8611
    write(client, 1, 0x6040, 0, 0x0080, size=2)
    [cleared] = frames_with_id(client.collect(0.01), 0x81)
    assert bytes(cleared.data) == bytes(8)


def test_emcy_behaviour_0_sends_nothing(client):
    write(client, 1, 0x205F, 0, 0, size=2)
    write(client, 1, 0x6040, 0, 0x8000, size=2)
    assert frames_with_id(client.collect(0.01), 0x81) == []


def test_default_pdos_sync_rtr_and_rpdo(client):
    client.send(0x000, bytes([0x01, 1]))
    client.collect(0.001)
    node = client.network.node(1)
    # TPDO3 (0x381, type 1): position actual value at every SYNC
    client.send(0x080)
    [tpdo3] = frames_with_id(client.collect(0.002), 0x381)
    assert struct.unpack("<i", bytes(tpdo3.data))[0] in range(node.store.get(0x6064) - 10, node.store.get(0x6064) + 1)
    # TPDO1 (0x181, type 253): only on a remote request
    node.store.set(0x6041, 0, 0x0237)
    assert frames_with_id(client.collect(0.01), 0x181) == []
    client.send(0x181, rtr=True, dlc=2)
    [tpdo1] = frames_with_id(client.collect(0.01), 0x181)
    assert bytes(tpdo1.data) == b"\x37\x02"
    # RPDO2 (0x301, type 255): target velocity applied on reception
    client.send(0x301, struct.pack("<i", -1234))
    client.collect(0.001)
    assert node.store.get(0x60FF) == -1234
    # RPDO3 (0x401, type 1): applied at the next SYNC only
    client.send(0x401, struct.pack("<i", 777))
    client.collect(0.001)
    assert node.store.get(0x60C1, 1) == 0
    client.send(0x080)
    client.collect(0.001)
    assert node.store.get(0x60C1, 1) == 777


def test_pdos_are_silent_outside_operational(client):
    client.send(0x301, struct.pack("<i", 55))
    client.send(0x080)
    messages = client.collect(0.01)
    assert frames_with_id(messages, 0x381) == [] and client.network.node(1).store.get(0x60FF) == 0
    assert client.network.node(1).behaviour.syncs == 1  # SYNC still reaches the drive in PRE-OPERATIONAL


def test_event_driven_tpdo_after_remapping(client):
    # TPDO2 -> event-driven (255), mapping: control word (16 bit) then target velocity
    write(client, 1, 0x1801, 2, 255, size=1)
    write(client, 1, 0x1A01, 0, 0, size=1)
    write(client, 1, 0x1A01, 1, 0x60400010)
    write(client, 1, 0x1A01, 2, 0x60FF0020)
    write(client, 1, 0x1A01, 0, 2, size=1)
    client.send(0x000, bytes([0x01, 1]))
    [initial] = frames_with_id(client.collect(0.01), 0x281)  # once on entering OPERATIONAL
    assert bytes(initial.data) == bytes(6)
    write(client, 1, 0x60FF, 0, 42)  # not the first mapped object: no transmission
    assert frames_with_id(client.collect(0.01), 0x281) == []
    write(client, 1, 0x6040, 0, 0x000F, size=2)
    [tpdo2] = frames_with_id(client.collect(0.01), 0x281)
    assert bytes(tpdo2.data) == struct.pack("<Hi", 0x000F, 42)


def test_mapping_checks_abort(client):
    response = client.sdo(1, bytes([0x23, 0x00, 0x1A, 1]) + struct.pack("<I", 0x10180120))
    assert struct.unpack_from("<I", response, 4)[0] == sdo_abort.CANNOT_BE_MAPPED
    for sub, entry in ((1, 0x60640020), (2, 0x60640020), (3, 0x60640020)):
        write(client, 1, 0x1A00, sub, entry)
    response = client.sdo(1, bytes([0x2F, 0x00, 0x1A, 0, 3]))
    assert struct.unpack_from("<I", response, 4)[0] == sdo_abort.PDO_LENGTH_EXCEEDED


def test_short_rpdo_raises_emcy_0x8210(client):
    client.send(0x000, bytes([0x01, 1]))
    client.send(0x301, b"\x01\x02")
    [emcy] = frames_with_id(client.collect(0.01), 0x81)
    assert struct.unpack_from("<H", bytes(emcy.data))[0] == 0x8210


def test_0x2000_makes_the_drive_start_every_node(client):
    write(client, 1, 0x2000, 0, 20, size=2)
    client.collect(0.01)
    assert client.network.node(2).state.value == "PRE-OPERATIONAL"
    messages = client.collect(0.02)
    assert [bytes(m.data) for m in frames_with_id(messages, 0x000)] == [b"\x01\x00"]
    assert {node.state.value for node in client.network.nodes.values()} == {"OPERATIONAL"}


def test_sync_producer(client):
    write(client, 2, 0x1006, 0, 20000)
    write(client, 2, 0x1005, 0, 0x40000080)
    syncs = frames_with_id(client.collect(0.1), 0x080)
    assert len(syncs) in (4, 5)
    assert client.network.node(1).behaviour.syncs == len(syncs)


def test_heartbeat_consumer_timeout_raises_drive_error_51(client):
    write(client, 1, 0x205E, 0, 1, size=2)
    write(client, 1, 0x1016, 1, (2 << 16) | 30)  # node 1 watches node 2's heartbeat, 30 ms
    write(client, 2, 0x1017, 0, 10, size=2)
    client.collect(0.05)
    assert client.network.node(1).behaviour.errors == []
    write(client, 2, 0x1017, 0, 0, size=2)  # node 2 falls silent
    messages = client.collect(0.05)
    assert client.network.node(1).behaviour.errors == [51]
    assert [struct.unpack_from("<HBB", bytes(m.data))[::2] for m in frames_with_id(messages, 0x81)] == [(0x8130, 51)]
