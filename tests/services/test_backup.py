"""Backup and restore against the simulated drives over socketcand and over the RS-232 link, with link cuts."""

from __future__ import annotations

import threading
import time

import pytest

from servostudio.formats.objectfile import read_object_file
from servostudio.services.backup import (
    BackupError,
    BackupPlaceRefused,
    RestoreValidationError,
    backup_file,
    restore_file,
    run_per_drive,
)
from servostudio.services.bus import ConnectionManager
from servostudio.services.scan import scan
from servostudio.sim.nmt import NmtState


@pytest.fixture(scope="module")
def connection(endpoint, commission):
    manager = ConnectionManager()
    bus = manager.open(endpoint.spec)
    assert bus.link.connected
    scan(bus)
    results = run_per_drive([bus.drive(node) for node in bus.nodes], commission)  # once per transport
    assert not [error for error in results.values() if isinstance(error, Exception)], results
    yield bus
    manager.close_all()


def _cut_at_start(endpoint):
    """A progress callback that cuts the link as soon as the transfers are queued (with slow drives: mid-way)."""

    def progress(event):
        if endpoint.server is not None:
            endpoint.cut()

    return progress


def _cut_after_first_step(endpoint):
    """Cut the link at the first progress step (5 % of the restore confirmed): some objects are written, most not."""

    def progress(event):
        if event["done"] > 0 and endpoint.server is not None:
            endpoint.cut()

    return progress


def _values(path):
    return {(entry.index, entry.sub): entry.value for entry in read_object_file(path)}


def test_backup_change_restore_read_back(connection, tmp_path):
    drive = connection.drive(1)
    original = tmp_path / "DRIVEPAR.TXT"
    result = backup_file(drive, original)
    assert result.objects > 300 and result.kind == "DRIVEPAR.TXT"
    saved = _values(original)
    kpv = drive.variable("0x60F9,2")
    assert saved[(0x60F9, 2)] == drive.read(kpv).raw

    changed_value = kpv.minimum if saved[(0x60F9, 2)] != kpv.minimum else kpv.maximum
    drive.write(kpv, changed_value)
    assert drive.read(kpv).raw == changed_value

    restored = restore_file(drive, original)
    assert restored.ok, restored.as_dict()
    assert restored.stored == "save"
    assert drive.read(kpv).raw == saved[(0x60F9, 2)]
    again = tmp_path / "again" / "DRIVEPAR.TXT"
    again.parent.mkdir()
    backup_file(drive, again)
    assert _values(again) == saved


def test_user_par_backup_contains_only_user_objects(connection, tmp_path):
    drive = connection.drive(2)
    path = tmp_path / "USER_PAR.TXT"
    result = backup_file(drive, path)
    assert result.kind == "USER_PAR.TXT"
    keys = _values(path)
    assert keys and all(drive.dictionary[key].save_type.value == "USER_PAR" for key in keys)


def test_corrupted_file_is_refused_with_its_line_and_nothing_is_written(connection, tmp_path, sim_network):
    drive = connection.drive(3)
    path = tmp_path / "DRIVEPAR.TXT"
    backup_file(drive, path)
    lines = path.read_text(encoding="latin-1").splitlines()
    kpv_line = next(number for number, line in enumerate(lines, 1) if line.startswith("0x60F9,2="))
    lines[kpv_line - 1] = "0x60F9,2=banana"
    pole_line = next(number for number, line in enumerate(lines, 1) if line.startswith("0x3410,1="))
    lines[pole_line - 1] = "0x3410,1=99"
    path.write_text("\n".join(lines) + "\n", encoding="latin-1")
    first_bad = min(kpv_line, pole_line)

    frames = []
    station = type("Spy", (), {"receive": lambda self, frame, timestamp: frames.append(frame)})()
    sim_network.attach(station)
    try:
        with pytest.raises(RestoreValidationError) as error:
            restore_file(drive, path)
    finally:
        sim_network.detach(station)
    assert f"DRIVEPAR.TXT:{first_bad}:" in str(error.value)
    assert "nothing was written to node 3" in str(error.value)
    assert not any(0x601 <= frame.can_id <= 0x67F and frame.data[0] & 0xE0 == 0x20 for frame in frames)


def test_link_cut_during_backup_leaves_no_file_and_link_recovers(connection, endpoint, sim_network, slow, tmp_path):
    drive = connection.drive(1)
    path = tmp_path / "DRIVEPAR.TXT"
    with slow(sim_network), pytest.raises(BackupError, match="no file written"):
        backup_file(drive, path, progress=_cut_at_start(endpoint))
    assert not path.exists()
    assert list(tmp_path.iterdir()) == []  # no temporary file left either
    endpoint.restore()
    assert connection.link.wait_connected(5.0)
    assert backup_file(drive, path).objects > 300


def test_link_cut_during_restore_says_what_was_written(connection, endpoint, sim_network, slow, tmp_path):
    drive = connection.drive(2)
    path = tmp_path / "DRIVEPAR.TXT"
    backup_file(drive, path)
    with slow(sim_network):
        result = restore_file(drive, path, progress=_cut_after_first_step(endpoint))
    assert not result.ok
    assert "objects had been written; nothing was stored to flash" in result.error
    statuses = {outcome.status for outcome in result.outcomes}
    assert "not written" in statuses and statuses & {"written", "verified"}  # exactly what reached the drive
    assert len(result.outcomes) == len(read_object_file(path))
    assert result.stored == ""
    endpoint.restore()
    assert connection.link.wait_connected(5.0)
    deadline = time.monotonic() + 5
    while not connection.link.connected and time.monotonic() < deadline:
        time.sleep(0.05)
    rerun = restore_file(drive, path)  # a failed restore can simply be run again
    assert rerun.ok, rerun.as_dict()


def test_a_drive_that_stops_answering_ends_the_restore_at_its_first_silent_write(
    connection, sim_network, slow, tmp_path
):
    """The bus stays up but node 3 goes silent (NMT stop) early in a restore: one write times out and the rest of
    the file is not sent at all (not one timeout per object); the result says what was written."""
    drive = connection.drive(3)
    path = tmp_path / "DRIVEPAR.TXT"
    backup_file(drive, path)
    node = sim_network.node(3)
    stop_posted = threading.Event()
    sent_while_silent = []

    def spy_receive(self, frame, timestamp):  # on the simulation thread, with the frame's delivery to node 3
        if node.state is NmtState.STOPPED and frame.can_id in (0x603, 0x643) and frame.data[0] & 0xE0 == 0x20:
            sent_while_silent.append(frame)  # a download request (direct or redirected) node 3 will not answer

    def progress(event):
        if event["done"] > 0 and not stop_posted.is_set():
            stop_posted.set()
            sim_network.post(lambda: node.nmt_command(0x02))  # NMT stop: no more SDO answers

    station = type("Spy", (), {"receive": spy_receive})()
    sim_network.attach(station)
    try:
        with slow(sim_network):
            result = restore_file(drive, path, progress=progress)
    finally:
        sim_network.detach(station)
        sim_network.post(lambda: node.nmt_command(0x80))  # back to pre-operational
    assert not result.ok and "no SDO response" in result.error
    assert "objects had been written; nothing was stored to flash" in result.error
    assert 1 <= len(sent_while_silent) <= 3, len(sent_while_silent)
    statuses = [outcome.status for outcome in result.outcomes]
    assert statuses.count("not written") > len(statuses) / 2 and "written" in statuses
    assert restore_file(drive, path).ok  # the node answers again: the same file simply goes in


def test_a_backup_makes_its_missing_folder_and_refuses_one_that_cannot_be(connection, tmp_path):
    drive = connection.drive(1)
    nested = tmp_path / "2026-12-02" / "line 3" / "DRIVEPAR.TXT"
    assert backup_file(drive, nested).objects > 300 and _values(nested)
    (tmp_path / "in the way").write_text("a file, not a folder")
    with pytest.raises(BackupPlaceRefused, match=r"cannot make the folder for DRIVEPAR\.TXT") as refused:
        backup_file(drive, tmp_path / "in the way" / "DRIVEPAR.TXT")
    assert str(tmp_path) not in str(refused.value)  # no server path in the message
