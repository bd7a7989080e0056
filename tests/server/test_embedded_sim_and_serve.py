"""The `sim` bus (simulated drives inside the server) and the serve command's localhost rule."""

from __future__ import annotations

import pytest

from servostudio.cli import check_bind_host
from servostudio.cli.output import CommandError
from servostudio.services.bus import ConnectionManager
from servostudio.services.scan import scan


def test_sim_bus_builds_and_stops_its_drives():
    manager = ConnectionManager()
    bus = manager.open("sim:4,7:cd1k")
    try:
        found = {info.node: info.device for info in scan(bus)}
        assert found == {4: "xtrapulspac", 7: "cd1k"}
        assert bus.simulation.running
    finally:
        manager.close_all()
    assert not bus.simulation.running
    assert manager.list() == []


@pytest.mark.parametrize("host", ["127.0.0.1", "::1", "localhost", "127.0.0.2"])
def test_serve_accepts_loopback(host):
    check_bind_host(host, allow_remote=False)


@pytest.mark.parametrize("host", ["0.0.0.0", "192.168.1.10", "example.org"])
def test_serve_refuses_other_addresses(host):
    with pytest.raises(CommandError, match="localhost only"):
        check_bind_host(host, allow_remote=False)
    check_bind_host(host, allow_remote=True)  # explicit opt-in, e.g. inside the container


def test_cd1k_restore_refuses_to_store_while_enabled(commission, tmp_path):
    from servostudio.drive.cia402 import State
    from servostudio.drive.control import set_state
    from servostudio.services.backup import BackupError, backup_file, restore_file

    manager = ConnectionManager()
    try:
        bus = manager.open("sim:5:cd1k")
        scan(bus)
        drive = bus.drive(5)
        commission(drive)
        path = tmp_path / "DRIVEPAR.TXT"
        backup_file(drive, path)
        set_state(drive, State.OPERATION_ENABLED)
        with pytest.raises(BackupError, match="only with the drive disabled; disable it first — nothing was written"):
            restore_file(drive, path)
        set_state(drive, State.SWITCH_ON_DISABLED)
        result = restore_file(drive, path)
        assert result.ok and result.stored == "save", result.as_dict()
    finally:
        manager.close_all()
