"""The built-in dictionaries and the real drive behaviours, reached by independent peers over socketcand."""

from __future__ import annotations

import time
from pathlib import Path

import canopen
import pytest
from canopen.profiles.p402 import BaseNode402
from canopen.sdo.exceptions import SdoAbortedError

from servostudio.formats.objectfile import read_object_file
from servostudio.od.library import BUILTIN_EDS_DIR
from servostudio.sim import sdo_abort
from servostudio.sim.flash import SAVE
from servostudio.sim.network import SimulatedNetwork
from servostudio.sim.socketcand import SocketcandServer

XTRAPULSPAC_EDS = str(Path(BUILTIN_EDS_DIR) / "xtrapulspac.eds")


@pytest.fixture(scope="module")
def bus(tmp_path_factory):
    state_dir = tmp_path_factory.mktemp("flash")
    network = SimulatedNetwork("1,2", state_dir=state_dir)
    network.start()
    server = SocketcandServer(network, port=0).start()
    host, port = server.address
    client = canopen.Network()
    client.connect(interface="socketcand", host=host, port=port, channel="can0")
    yield client, network, state_dir
    client.disconnect()
    server.stop()
    network.stop()


def remote(client, node_id, cls=canopen.RemoteNode):
    node = cls(node_id, XTRAPULSPAC_EDS)
    node.sdo.RESPONSE_TIMEOUT = 5.0
    client.add_node(node)
    return node


def test_identity_parameters_and_aborts_of_the_xtrapulspac(bus):
    client, network, _ = bus
    node = remote(client, 2)
    assert node.sdo[0x1018][1].raw == network.node(2).store.od.vendor_id
    assert node.sdo[0x1014].raw == 0x82
    assert node.sdo[0x1000].raw == network.node(2).store.get(0x1000)
    with pytest.raises(SdoAbortedError) as raised:
        node.sdo[0x6041].raw = 0
    assert raised.value.code == sdo_abort.READ_ONLY
    with pytest.raises(SdoAbortedError) as raised:
        node.sdo.upload(0x1234, 0)
    assert raised.value.code == sdo_abort.OBJECT_DOES_NOT_EXIST


def test_block_transfers_of_the_firmware_buffer(bus):
    client, _network, _ = bus
    node = remote(client, 1)
    data = bytes((i * 13) & 0xFF for i in range(4096 + 77))
    with node.sdo[0x5F32][5].open("wb", size=len(data), block_transfer=True) as stream:
        stream.write(data)
    with node.sdo[0x5F32][5].open("rb", block_transfer=True) as stream:
        assert stream.read() == data


def test_cia402_state_machine_with_basenode402(bus):
    client, _network, _ = bus
    node = remote(client, 2, BaseNode402)
    node.nmt.state = "PRE-OPERATIONAL"
    node.sdo[0x1800][2].raw = 255  # status word event-driven, so canopen's 402 helper sees every change
    node.setup_402_state_machine(read_pdos=True)
    node.nmt.state = "OPERATIONAL"
    for state in ("READY TO SWITCH ON", "SWITCHED ON", "OPERATION ENABLED"):
        node.state = state
        assert node.state == state
    node.state = "SWITCH ON DISABLED"
    node.nmt.state = "PRE-OPERATIONAL"


def test_save_to_flash_writes_drivepar(bus):
    client, network, state_dir = bus
    node = remote(client, 1)
    saved = next(
        var
        for var in network.node(1).store.od.variables()
        if var.save_type.value == "DRIVEPAR"
        and var.access.writable
        and var.data_type.is_integer
        and var.minimum is not None
        and var.maximum is not None
        and var.maximum > var.minimum
    )
    value = saved.minimum + 1
    node.sdo.download(
        saved.index,
        saved.subindex,
        saved.data_type.size and value.to_bytes(saved.data_type.size, "little", signed=saved.data_type.is_signed),
    )
    node.sdo[0x1010][1].raw = SAVE
    deadline = time.monotonic() + 10
    while node.sdo[0x1010][1].raw != 5 and time.monotonic() < deadline:
        time.sleep(0.05)
    entries = {(e.index, e.sub): e.value for e in read_object_file(state_dir / "node1" / "DRIVEPAR.TXT")}
    assert entries[(saved.index, saved.subindex)] == value
    assert all(network.node(1).store.od[key].save_type.value == "DRIVEPAR" for key in entries)


def test_mixed_devices_answer_with_their_own_identity(raw_client):
    network = SimulatedNetwork("1:xtrapulspac,2:cd1k,3:encotrive", bitrate=None)
    client = raw_client(network)
    client.collect(0.001)
    for node_id, device in ((1, "xtrapulspac"), (2, "cd1k"), (3, "encotrive")):
        response = client.sdo(node_id, bytes([0x40, 0x18, 0x10, 0x01]))
        assert network.node(node_id).store.od.device == device
        assert int.from_bytes(response[4:8], "little") == network.node(node_id).store.od.vendor_id


def test_real_drive_reports_a_bad_drivepar_with_emcy_and_fault(tmp_path, raw_client):
    (tmp_path / "node4").mkdir()
    (tmp_path / "node4" / "DRIVEPAR.TXT").write_text("0x9999,0=1\n")
    network = SimulatedNetwork("4", state_dir=tmp_path)
    client = raw_client(network)
    emcys = [m for m in client.collect(0.01) if m.arbitration_id == 0x84]
    assert [m.data[3] for m in emcys] == [42]  # Infranor code; the CiA code is the drive model's catalogue
    assert network.node(4).store.get(0x6041) & 0x0008  # status word: fault
