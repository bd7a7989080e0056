"""The RS-232 python-can plugin: canopen works unchanged through redirection and the firmware quirk."""

from __future__ import annotations

import can
import canopen
import pytest

from servostudio.transport.rs232 import host_to_link, link_to_host


def test_identifier_mapping():
    assert host_to_link(0x601, None) == 0x641
    assert host_to_link(0x63F, None) == 0x67F
    assert host_to_link(0x601, 1) == 0x601
    assert host_to_link(0x602, 1) == 0x642
    assert host_to_link(0x000, None) == 0x000
    assert host_to_link(0x641, None) == 0x641
    assert link_to_host(0x5C3) == 0x583
    assert link_to_host(0x603) == 0x583
    assert link_to_host(0x643) == 0x583
    assert link_to_host(0x583) == 0x583
    assert link_to_host(0x083) == 0x083


@pytest.mark.parametrize("quirk", [False, True])
def test_canopen_sdo_through_the_link(slaves, gateway, quirk):
    link = gateway(quirk=quirk)
    network = canopen.Network()
    network.connect(interface="servostudio_rs232", channel=link.url, baudrate=115200)
    try:
        node = network.add_node(5, canopen.ObjectDictionary())
        node.sdo.RESPONSE_TIMEOUT = 1.0
        assert int.from_bytes(node.sdo.upload(0x2003, 0), "little") == 123456
        assert node.sdo.upload(0x2004, 0) == b"axis name longer than four"  # segmented
        node.sdo.download(0x2002, 0, (-7).to_bytes(2, "little", signed=True))
        assert slaves[5].sdo[0x2002].raw == -7
        assert 0x645 in link.seen_from_host and 0x605 not in link.seen_from_host
    finally:
        network.disconnect()


def test_lost_link_raises_can_operation_error(slaves, gateway):
    link = gateway()
    bus = can.Bus(interface="servostudio_rs232", channel=link.url)
    try:
        bus.send(can.Message(arbitration_id=0x601, data=bytes([0x40, 0, 0x10, 0, 0, 0, 0, 0]), is_extended_id=False))
        assert bus.recv(2.0).arbitration_id == 0x581
        link.cut()
        with pytest.raises(can.CanOperationError, match="serial link lost"):
            for _ in range(50):
                bus.recv(0.1)
    finally:
        bus.shutdown()


def test_refuses_frames_the_link_cannot_carry(slaves, gateway):
    link = gateway()
    bus = can.Bus(interface="servostudio_rs232", channel=link.url)
    try:
        with pytest.raises(can.CanOperationError, match="11-bit data frames"):
            bus.send(can.Message(arbitration_id=0x1234567, data=b"", is_extended_id=True))
    finally:
        bus.shutdown()
