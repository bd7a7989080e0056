"""The SDO engine against canopen slaves on a python-can virtual bus."""

from __future__ import annotations

import can
import pytest

from servostudio.drive.link import BusLink
from servostudio.drive.sdo import SdoAbortError, SdoEngine, SdoLinkError, SdoTimeoutError


@pytest.fixture
def engine(slaves, virtual_channel):
    link = BusLink("test", lambda: can.Bus(interface="virtual", channel=virtual_channel, receive_own_messages=False))
    assert link.start(wait=2.0)
    yield SdoEngine(link, timeout=0.3)
    link.close()


def test_expedited_and_segmented_uploads(engine):
    assert engine.upload(1, 0x1000, 0).result(2) == (0x00020192).to_bytes(4, "little")
    assert engine.upload(5, 0x2002, 0).result(2) == (-300).to_bytes(2, "little", signed=True)
    assert engine.upload(5, 0x2004, 0).result(2) == b"axis name longer than four"


def test_downloads_reach_the_slave(engine, slaves):
    engine.download(1, 0x2003, 0, (987654).to_bytes(4, "little")).result(2)
    assert slaves[1].sdo[0x2003].raw == 987654
    engine.download(5, 0x2004, 0, b"a new, long axis name!").result(2)  # segmented, 4 segments
    assert slaves[5].sdo[0x2004].raw == "a new, long axis name!"
    assert engine.upload(5, 0x2004, 0).result(2) == b"a new, long axis name!"


def test_many_transfers_to_several_nodes_complete_in_order(engine, slaves):
    futures = [(node, value, engine.download(node, 0x2003, 0, value.to_bytes(4, "little")))
               for value in range(20) for node in (1, 5)]
    for _, _, future in futures:
        future.result(5)
    assert slaves[1].sdo[0x2003].raw == 19 and slaves[5].sdo[0x2003].raw == 19
    reads = [engine.upload(node, 0x2001, 0) for node in (1, 5) for _ in range(10)]
    assert all(future.result(5) == b"\x07" for future in reads)


def test_abort_names_node_object_and_meaning(engine):
    with pytest.raises(SdoAbortError) as error:
        engine.upload(1, 0x2FFF, 0).result(2)
    assert error.value.code == 0x06020000
    assert str(error.value) == ("node 1, object 0x2FFF,0: object does not exist in the object dictionary "
                                "(SDO abort 0x06020000)")


def test_timeout_names_node_and_object(engine):
    with pytest.raises(SdoTimeoutError, match=r"node 9, object 0x1000,0: no SDO response within 300 ms"):
        engine.upload(9, 0x1000, 0).result(3)
    # The node's queue goes on after a timeout.
    assert engine.upload(1, 0x2001, 0).result(2) == b"\x07"


def test_link_down_fails_transfers_clearly(engine):
    engine.link.close()
    with pytest.raises(SdoLinkError, match="not connected"):
        engine.upload(1, 0x2001, 0).result(2)
