"""The XtrapulsPac RS-232 link against the simulator: every drive reached through the one on the cable."""

from __future__ import annotations

import time

import pytest

from servostudio.drive.access import DriveAccessError
from servostudio.formats.objectfile import read_object_file
from servostudio.services.backup import backup_file, restore_file
from servostudio.services.bus import ConnectionManager
from servostudio.services.scan import scan


@pytest.fixture(scope="module")
def serial_bus(serial_line):
    manager = ConnectionManager()
    events: list[dict] = []
    manager.events.add_listener(events.append)
    bus = manager.open(serial_line.spec)
    assert bus.link.connected
    bus.events_seen = events
    yield bus
    manager.close_all()


def test_scan_over_serial_reaches_every_drive(serial_bus):
    found = scan(serial_bus)
    assert [info.node for info in found] == [1, 2, 3]
    assert all(info.device == "xtrapulspac" for info in found)


@pytest.mark.parametrize("node", [1, 3])
def test_read_and_write_through_the_gateway(serial_bus, node):
    scan(serial_bus, nodes=[node])
    drive = serial_bus.drive(node)
    filter_var = drive.variable("0x60F9,2")
    old = drive.read(filter_var).raw
    new = filter_var.minimum if old != filter_var.minimum else filter_var.maximum
    drive.write(filter_var, new)
    assert drive.read(filter_var).raw == new
    drive.write(filter_var, old)
    drive.write("0x2004", f"serial axis {node}")  # segmented both ways through the link
    assert drive.read("0x2004").raw.rstrip("\0") == f"serial axis {node}"
    with pytest.raises(DriveAccessError, match="read-only"):
        drive.write("statusword", 0)


def test_user_par_backup_and_restore_over_serial(serial_bus, tmp_path):
    scan(serial_bus, nodes=[2])
    drive = serial_bus.drive(2)
    path = tmp_path / "USER_PAR.TXT"
    assert backup_file(drive, path).objects > 50
    entries = read_object_file(path)
    first = drive.variable((entries[0].index, entries[0].sub))
    drive.write(first, first.maximum if entries[0].value != first.maximum else first.minimum)
    result = restore_file(drive, path, store=False)
    assert result.ok, result.as_dict()
    assert drive.read(first).raw == entries[0].value


def test_link_loss_is_reported_and_recovered(serial_bus, serial_line):
    def lost_events():
        return [event for event in serial_bus.events_seen if event["type"] == "bus_state" and not event["connected"]]

    serial_line.cut()
    deadline = time.monotonic() + 5
    while not lost_events() and time.monotonic() < deadline:
        time.sleep(0.02)
    assert not serial_bus.link.connected
    assert "serial link lost" in lost_events()[0]["reason"]
    serial_line.restore()
    assert serial_bus.link.wait_connected(5.0)
    scan(serial_bus, nodes=[1])
    assert serial_bus.drive(1).read("0x1000").raw > 0
