"""Flash files: 0x1010/0x1011 signatures, DRIVEPAR.TXT / USER_PAR.TXT in the state directory, busy flag, reset node."""

from __future__ import annotations

import struct

import pytest
from tests.support.sim_test_drive import frames_with_id, write

from servostudio.formats.objectfile import read_object_file
from servostudio.sim.flash import LOAD, LOAD_USER, SAVE, signature
from servostudio.sim.network import SimulatedNetwork


def test_signatures_are_little_endian_ascii():
    assert signature("save") == 0x65766173 and SAVE == 0x65766173
    assert LOAD == 0x64616F6C and LOAD_USER == 0x7273756C


@pytest.fixture
def client(make_network, raw_client, tmp_path):
    network = make_network("1,2", state_dir=tmp_path)
    client = raw_client(network)
    client.collect(0.001)
    return client


def drivepar(tmp_path, node_id=1):
    return {(e.index, e.sub): e.value for e in read_object_file(tmp_path / f"node{node_id}" / "DRIVEPAR.TXT")}


def test_save_writes_drivepar_objects_and_sets_busy_while_saving(client, tmp_path):
    write(client, 1, 0x6083, 0, 4242)
    write(client, 1, 0x60FF, 0, 99)  # USER_PAR save type: not in DRIVEPAR.TXT
    write(client, 1, 0x1010, 1, SAVE)
    node = client.network.node(1)
    assert node.events.flash_busy and node.store.get(0x6041) & 0x8000
    assert client.sdo(1, bytes([0x40, 0x10, 0x10, 1]))[4] == 2  # status: running
    client.collect(0.3)
    assert not node.events.flash_busy and node.store.get(0x6041) & 0x8000 == 0
    assert client.sdo(1, bytes([0x40, 0x10, 0x10, 1]))[4] == 5  # status: done
    assert drivepar(tmp_path) == {(0x1017, 0): 0, (0x2004, 0): "axis", (0x6083, 0): 4242}
    assert not (tmp_path / "node2").exists()


def test_save_confirmation_waits_for_the_end_when_0x205d_bit5_is_set(client):
    write(client, 1, 0x205D, 0, 0x20, size=2)
    client.send(0x601, bytes([0x23, 0x10, 0x10, 1]) + struct.pack("<I", SAVE))
    assert frames_with_id(client.collect(0.1), 0x581) == []
    [confirmation] = frames_with_id(client.collect(0.2), 0x581)
    assert confirmation.data[0] == 0x60


def test_other_values_are_ignored(client, tmp_path):
    write(client, 1, 0x1010, 1, 0x12345678)
    client.collect(0.3)
    assert not (tmp_path / "node1").exists()


def test_load_restores_saved_values_and_reset_node_reloads_them(client, tmp_path):
    write(client, 1, 0x6083, 0, 777)
    write(client, 1, 0x1010, 1, SAVE)
    client.collect(0.3)
    write(client, 1, 0x6083, 0, 1)
    write(client, 1, 0x1011, 1, LOAD)
    assert client.network.node(1).store.get(0x6083) == 777
    client.collect(0.3)
    write(client, 1, 0x6083, 0, 2)
    write(client, 1, 0x205D, 0, 1, size=2)  # reset node reloads DRIVEPAR.TXT
    client.send(0x000, bytes([0x81, 1]))
    client.collect(0.01)
    assert client.network.node(1).store.get(0x6083) == 777


def test_warm_reset_restores_defaults_then_files_and_resets_the_behaviour(client, tmp_path):
    write(client, 1, 0x2004, 0, 0x41414141)  # "AAAA": saved
    write(client, 1, 0x1010, 1, SAVE)
    client.collect(0.3)
    write(client, 1, 0x60C1, 1, 5)  # not saved
    write(client, 1, 0x205D, 0, 2, size=2)
    client.send(0x000, bytes([0x81, 1]))
    client.collect(0.01)
    node = client.network.node(1)
    assert node.store.get(0x2004) == "AAAA" and node.store.get(0x60C1, 1) == 0 and node.behaviour.resets == 1
    assert node.store.get(0x205D) == 0  # back to its default: 0x205D itself is not saved


def test_drivepar_is_read_at_power_on(make_network, tmp_path):
    (tmp_path / "node3").mkdir()
    (tmp_path / "node3" / "DRIVEPAR.TXT").write_text("; saved by hand\n0x6083,0=31337\n0x2004,0=name\n")
    network = make_network("3", state_dir=tmp_path)
    assert network.node(3).store.get(0x6083) == 31337 and network.node(3).store.get(0x2004) == "name"


def test_user_parameters_with_an_error_are_refused_as_a_whole(client, tmp_path):
    folder = tmp_path / "node1"
    folder.mkdir()
    (folder / "USER_PAR.TXT").write_text("0x60FF,0=12\n0x6083,0=0\n")  # second line below the low limit
    write(client, 1, 0x1011, 1, LOAD_USER)
    [emcy] = frames_with_id(client.collect(0.01), 0x81)
    assert struct.unpack_from("<HBB", bytes(emcy.data)) == (0x6320, 0x01, 43)
    assert client.network.node(1).store.get(0x60FF) == 0
    client.collect(0.3)
    assert client.sdo(1, bytes([0x40, 0x11, 0x10, 1]))[4] == 4  # status: error
    (folder / "USER_PAR.TXT").write_text("0x60FF,0=12\n")
    write(client, 1, 0x1011, 1, LOAD_USER)
    assert client.network.node(1).store.get(0x60FF) == 12


def test_bad_drivepar_at_power_on_raises_error_42_once_booted(make_network, tmp_path):
    (tmp_path / "node1").mkdir()
    (tmp_path / "node1" / "DRIVEPAR.TXT").write_text("0x6083,0=12\n0x7777,0=1\n")
    network = make_network("1", state_dir=tmp_path)
    assert network.node(1).behaviour.errors == []
    network.advance(0.001)
    assert network.node(1).behaviour.errors == [42]
    assert network.node(1).store.get(0x6083) == 65536  # nothing of the file applied
    assert "0x7777,0 is not in the testdrive dictionary" in network.node(1).flash.last_error


PHASING = {1: 6, 2: 21845, 3: 49429}
"""0x3410,1-3 (pole pairs, phase order, sensor offset) as `apha` leaves them, unlike the catalogue's motor data."""


def _phased_and_saved(client) -> None:
    """Motor data from a catalogue (0x6410,14-16, copied into 0x3410 when written), then a phasing that found other
    commutation values, then a save: the file holds both, 0x3410 before 0x6410."""
    for sub, value in ((14, 4), (15, 21845), (16, 0)):
        write(client, 1, 0x6410, sub, value, size=2)
    for sub, value in PHASING.items():
        write(client, 1, 0x3410, sub, value, size=2)
    write(client, 1, 0x1010, 1, SAVE)
    client.collect(0.3)


def test_a_saved_phasing_survives_a_load_a_warm_reset_and_a_power_on(raw_client, tmp_path):
    """The XtrapulsPac's copy rule 0x6410 → 0x3410 is a user's write of motor data; restoring the saved image is not
    one: what `apha` found and the user saved is what the drive commutates with after a LOAD, a warm reset and a
    power-on."""
    client = raw_client(_xtrapulspac(tmp_path))
    client.collect(0.001)
    _phased_and_saved(client)
    assert {sub: drivepar(tmp_path)[0x3410, sub] for sub in PHASING} == PHASING
    store = client.network.node(1).store
    write(client, 1, 0x1011, 1, LOAD)
    assert {sub: store.get(0x3410, sub) for sub in PHASING} == PHASING
    write(client, 1, 0x205D, 0, 2, size=2)
    client.send(0x000, bytes([0x81, 1]))
    client.collect(0.01)
    assert {sub: client.network.node(1).store.get(0x3410, sub) for sub in PHASING} == PHASING
    powered_on = _xtrapulspac(tmp_path).node(1).store
    assert {sub: powered_on.get(0x3410, sub) for sub in PHASING} == PHASING
    assert powered_on.get(0x6410, 14) == 4  # the motor data stays the catalogue's


def _xtrapulspac(state_dir) -> SimulatedNetwork:
    return SimulatedNetwork("1", device="xtrapulspac", state_dir=state_dir)
