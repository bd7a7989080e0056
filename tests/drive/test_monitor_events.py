"""Bus monitor and event hub on a python-can virtual bus: EMCY, boot-up, NMT state, heartbeat loss and return."""

from __future__ import annotations

import asyncio
import time

import can
import pytest

from servostudio.drive.link import BusLink
from servostudio.drive.monitor import BusMonitor
from servostudio.drive.profiles import profile_for
from servostudio.services.bus import EventHub


def _wait_for(events, predicate, timeout=3.0):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        found = [event for event in events if predicate(event)]
        if found:
            return found[0]
        time.sleep(0.01)
    raise AssertionError(f"no matching event in {events}")


@pytest.fixture
def monitored(virtual_channel):
    events: list[dict] = []
    link = BusLink("test", lambda: can.Bus(interface="virtual", channel=virtual_channel, receive_own_messages=False))
    monitor = BusMonitor(link, events.append, lambda node: profile_for("xtrapulspac"))
    monitor.watch_statusword(3, 0x183)
    assert link.start(wait=2.0)
    drive_side = can.Bus(interface="virtual", channel=virtual_channel, receive_own_messages=False)
    yield events, drive_side
    drive_side.shutdown()
    link.close()


def _send(bus, cob_id, data):
    bus.send(can.Message(arbitration_id=cob_id, data=bytes(data), is_extended_id=False))


def test_emcy_is_decoded_with_the_manual_text(monitored):
    events, drive = monitored
    _send(drive, 0x083, [0x11, 0x86, 0x01, 35, 0, 0, 0, 0])
    event = _wait_for(events, lambda item: item["type"] == "emcy")
    assert event["node"] == 3 and event["bus"] == "test"
    assert event["faults"][0]["name"] == "Position following error"


def test_statusword_pdo_reports_state_changes_once(monitored):
    events, drive = monitored
    for statusword in (0x0240, 0x0240, 0x0221, 0x0227):
        _send(drive, 0x183, statusword.to_bytes(2, "little") + bytes(2))
    _wait_for(events, lambda item: item["type"] == "drive_state" and item["state"] == "OPERATION ENABLED")
    states = [item["state"] for item in events if item["type"] == "drive_state"]
    assert states == ["SWITCH ON DISABLED", "READY TO SWITCH ON", "OPERATION ENABLED"]


def test_bootup_state_change_heartbeat_loss_and_return(monitored):
    events, drive = monitored
    _send(drive, 0x705, [0x00])
    _wait_for(events, lambda item: item["type"] == "bootup" and item["node"] == 5)
    for _ in range(3):
        _send(drive, 0x705, [0x7F])
        time.sleep(0.05)
    _wait_for(events, lambda item: item["type"] == "nmt_state" and item["nmt_state"] == "PRE-OPERATIONAL")
    lost = _wait_for(events, lambda item: item["type"] == "heartbeat_lost", timeout=2.0)
    assert lost["node"] == 5
    _send(drive, 0x705, [0x05])
    _wait_for(events, lambda item: item["type"] == "heartbeat_back" and item["nmt_state"] == "OPERATIONAL")


def test_event_hub_delivers_to_asyncio_subscribers_from_any_thread():
    async def scenario():
        hub = EventHub()
        only_emcy = hub.subscribe({"emcy"})
        everything = hub.subscribe()
        await asyncio.to_thread(hub.publish, {"type": "progress", "done": 1})
        await asyncio.to_thread(hub.publish, {"type": "emcy", "node": 2})
        assert (await asyncio.wait_for(everything.get(), 1))["type"] == "progress"
        assert (await asyncio.wait_for(everything.get(), 1))["type"] == "emcy"
        assert (await asyncio.wait_for(only_emcy.get(), 1))["node"] == 2
        only_emcy.close()
        hub.publish({"type": "emcy", "node": 3})
        await asyncio.sleep(0.01)
        assert only_emcy.queue.empty()

    asyncio.run(scenario())
