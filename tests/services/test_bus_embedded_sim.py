"""The `sim` bus (simulated drives inside the server): built and stopped with the bus, and a CD1-k restore on it."""

from __future__ import annotations

import pytest
from tests.support.motion import controlling

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
        with controlling(manager, bus.id, 5):
            set_state(drive, State.OPERATION_ENABLED)
        with pytest.raises(BackupError, match="only with the drive disabled; disable it first — nothing was written"):
            restore_file(drive, path)
        set_state(drive, State.SWITCH_ON_DISABLED)
        result = restore_file(drive, path)
        assert result.ok and result.stored == "save", result.as_dict()
    finally:
        manager.close_all()
