"""Faults of a simulated XtrapulsPac: EMCY event with the manual's text, fault report, no silent reset, reset."""

from __future__ import annotations

import time

import pytest
from tests.support.motion import controlling

from servostudio.drive.cia402 import State
from servostudio.drive.control import StateChangeError, fault_report, read_state, reset_faults, set_state
from servostudio.services.bus import ConnectionManager
from servostudio.services.scan import scan


@pytest.fixture
def bus(socketcand):
    manager = ConnectionManager()
    events: list[dict] = []
    manager.events.add_listener(events.append)
    connection = manager.open(socketcand.spec)
    scan(connection, nodes=[1])
    connection.events_seen = events
    connection.manager = manager
    yield connection
    manager.close_all()


def test_software_limit_fault_is_reported_and_reset(bus):
    drive = bus.drive(1)
    # A linear axis whose software limits exclude the present position (0): enabling trips error 36.
    drive.write("0x607D,1", 100000)
    drive.write("0x607D,2", 200000)
    drive.write("0x3360", 1)
    try:
        with (
            controlling(bus.manager, bus.id, 1),
            pytest.raises(StateChangeError, match=r"node 1: in FAULT.*\(Software position limit\); reset the fault"),
        ):
            set_state(drive, State.OPERATION_ENABLED)
        report = fault_report(drive)
        assert report.state == "FAULT" and report.error_code == 0x8680
        assert [(fault.code, fault.name) for fault in report.faults] == [(36, "Software position limit")]
        deadline = time.monotonic() + 3
        while not [event for event in bus.events_seen if event["type"] == "emcy"] and time.monotonic() < deadline:
            time.sleep(0.02)
        emcy = next(event for event in bus.events_seen if event["type"] == "emcy")
        assert emcy["node"] == 1 and emcy["cia402_code"] == 0x8680
        assert emcy["faults"][0]["name"] == "Software position limit"
    finally:
        drive.write("0x3360", 0)  # a rotary axis again: the cause is gone
    reset_faults(drive)
    assert read_state(drive)[0] is State.SWITCH_ON_DISABLED
    assert fault_report(drive).faults == []
