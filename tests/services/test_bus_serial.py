"""What only the RS-232 link has: scan range 1–63, a real (pseudo-)terminal device, link-loss events.

Reads, writes, backup and restore over the link run in tests/drive/test_drive_access.py and
tests/services/test_backup.py, which take every test through socketcand and through the serial line.
"""

from __future__ import annotations

import time

import pytest

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


def test_scan_over_serial_reaches_every_drive_through_the_gateway(serial_bus, serial_line):
    found = scan(serial_bus)
    assert [info.node for info in found] == [1, 2, 3]
    assert all(info.device == "xtrapulspac" for info in found)
    assert serial_line.gateway.node.node_id == 1  # nodes 2 and 3 answered through redirection


def test_pseudo_terminal_like_a_real_serial_port(sim_network):
    from servostudio.sim.serial_link import SerialGateway, SerialPty

    gateway = SerialGateway(sim_network)
    terminal = SerialPty(gateway).start()
    manager = ConnectionManager()
    try:
        bus = manager.open(f"serial:{terminal.path}@57600")
        assert bus.link.connected, bus.link.last_error
        assert [info.node for info in scan(bus, nodes=[2, 9])] == [2]
        assert bus.drive(2).read("0x1000").raw > 0
    finally:
        manager.close_all()
        terminal.stop()
        gateway.close()


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
    back = [event for event in serial_bus.events_seen if event["type"] == "bus_state" and event["connected"]]
    assert back
    scan(serial_bus, nodes=[1])
    assert serial_bus.drive(1).read("0x1000").raw > 0
