"""Faults never hang the server's work: a bus closed under a scan, a multi-read or backup jobs; a drive reset in
the middle of a backup; line noise on the RS-232 link; a link cut during a sequence restore. Each ends at once with a
clear error, and the next attempt works once the fault is gone."""

from __future__ import annotations

import threading
import time

import pytest
from tests.support.relay import TcpRelay
from tests.support.sim_endpoints import SerialEndpoint, slow_drives

from servostudio.formats.sequence import Sequence, SequenceTable, SequenceType, write_sequence_file
from servostudio.services.backup import BackupError, FileKind, backup_file, restore_file
from servostudio.services.bus import ConnectionManager, JobRegistry
from servostudio.services.scan import ScanInterrupted, scan
from servostudio.services.terminal import read_objects
from servostudio.services.transfers import start_backup

PROMPT = 2.0  # seconds: "at once" for work that would otherwise wait for ever


class InThread:
    """Run ``work`` in a thread and keep what it returned or raised."""

    def __init__(self, work) -> None:
        self.result: object = None
        self.error: BaseException | None = None
        self.thread = threading.Thread(target=self._run, args=(work,), daemon=True)
        self.thread.start()

    def _run(self, work) -> None:
        try:
            self.result = work()
        except BaseException as error:  # noqa: BLE001 -- handed to the test
            self.error = error

    def ended_within(self, seconds: float) -> bool:
        self.thread.join(seconds)
        return not self.thread.is_alive()


@pytest.fixture
def embedded():
    """The server's embedded simulated bus, scanned, in a manager of its own (a test closes it)."""
    manager = ConnectionManager()
    connection = manager.open("sim", wait=5.0)
    assert connection.link.wait_connected(5.0)
    connection.engine.timeout = 1.0
    scan(connection)
    yield manager, connection
    manager.close_all()


def test_a_scan_in_flight_ends_at_once_when_its_bus_closes(embedded):
    manager, connection = embedded
    scanning = InThread(lambda: scan(connection))
    time.sleep(0.05)  # the probes of every node are on the wire
    manager.close("sim")
    assert scanning.ended_within(PROMPT)
    assert isinstance(scanning.error, ScanInterrupted) and "bus sim was closed" in str(scanning.error)
    assert sorted(connection.nodes) == [1, 2, 3]  # silence on a closed bus forgets no node


def test_a_multi_read_in_flight_ends_at_once_when_its_bus_closes(embedded):
    manager, connection = embedded
    drive = connection.drive(1)
    with slow_drives(connection.simulation):
        reading = InThread(lambda: read_objects(drive, ["statusword"] * 200))
        time.sleep(0.1)
        manager.close("sim")
        assert reading.ended_within(PROMPT)
    rows = reading.result
    assert len(rows) == 200 and rows[0]["value"] is not None
    assert "was closed" in rows[-1]["error"]


def test_backup_jobs_running_when_their_bus_closes_end_failed(embedded, tmp_path):
    manager, connection = embedded
    connection.engine.timeout = 30.0  # the close ends them, not a timeout (which a loaded host would reach first)
    jobs = JobRegistry(connection.events)
    with slow_drives(connection.simulation):
        started = [start_backup(jobs, connection, [tmp_path], str(tmp_path / f"job{n}"), None, None) for n in range(10)]
        time.sleep(0.3)
        jobs.cancel(started[0].id)
        manager.close("sim")
        deadline = time.monotonic() + PROMPT
        while any(job.state == "running" for job in started) and time.monotonic() < deadline:
            time.sleep(0.02)
    assert [job.state for job in started] == ["cancelled"] + ["failed"] * 9
    for job in started[1:]:
        assert set(job.result) == {"1", "2", "3"} and "3 of 3 failed" in job.error
        errors = [job.result[node]["error"] for node in job.result]
        assert all("was closed" in error for error in errors), errors
    assert not [path for path in tmp_path.rglob("*.TXT")]  # no file of a backup that did not complete


@pytest.fixture
def socketcand_bus(socketcand):
    manager = ConnectionManager()
    connection = manager.open(socketcand.spec)
    scan(connection)
    yield connection
    manager.close_all()


def test_a_drive_reset_mid_backup_fails_it_cleanly_is_reported_and_the_next_backup_works(
    socketcand_bus, sim_network, tmp_path
):
    """A power-cycled drive (NMT reset-node) forgets the transfer in progress and boots again: the backup must not
    go on and mix values from before and after the reset."""
    drive = socketcand_bus.drive(1)
    drive.write((0x2010, 0), 1)  # send the boot-up message
    drive.write((0x205D, 0), 0)  # reset node = reset communication: the 0x2010 setting survives it
    events: list[dict] = []
    socketcand_bus.events.add_listener(events.append)
    node, path = sim_network.node(1), tmp_path / "DRIVEPAR.TXT"

    def power_cycle(event: dict) -> None:
        if event["done"] > 0 and not any(e.get("type") == "reset sent" for e in events):
            events.append({"type": "reset sent"})
            sim_network.post(lambda: node.nmt_command(0x81))

    try:
        with slow_drives(sim_network), pytest.raises(BackupError, match="restarted") as failed:
            backup_file(drive, path, progress=power_cycle)
        assert "no file written" in str(failed.value) and not path.exists()
        assert any(event.get("type") == "bootup" and event.get("node") == 1 for event in events)
        assert backup_file(drive, path).objects > 300
    finally:
        socketcand_bus.events.remove_listener(events.append)
        drive.write((0x2010, 0), 0)
        drive.write((0x205D, 0), 2)


@pytest.fixture
def noisy_serial(sim_network):
    """The RS-232 link of node 1 through a relay that adds line noise."""
    line = SerialEndpoint(sim_network, quirk=True)
    relay = TcpRelay(("127.0.0.1", line.port))
    manager = ConnectionManager()
    connection = manager.open(f"serial:socket://127.0.0.1:{relay.port}@115200")
    scan(connection, [1, 2])
    yield relay, connection
    manager.close_all()
    relay.close()
    line.close()


def _entries(path):
    return [line for line in path.read_text(encoding="latin-1").splitlines() if not line.startswith(";")]


def test_line_noise_between_frames_and_a_corrupted_answer_are_survived(noisy_serial, tmp_path):
    relay, connection = noisy_serial
    drive = connection.drive(2)  # reached through the gateway drive's redirection
    clean = backup_file(drive, tmp_path / "clean.TXT", FileKind.DRIVEPAR)

    done: set[str] = set()

    def noise(event: dict) -> None:  # once each, a quarter and half-way through
        if event["done"] >= event["total"] // 4 and "noise" not in done:
            done.add("noise")
            relay.insert(bytes(range(256)) * 2)  # garbage between frames: the decoder resynchronises
        if event["done"] >= event["total"] // 2 and "corruption" not in done:
            done.add("corruption")
            relay.corrupt(12)  # one answer destroyed: the read is sent again

    noisy = backup_file(drive, tmp_path / "noisy.TXT", FileKind.DRIVEPAR, progress=noise)
    assert relay.disturbed == 512 + 12
    assert noisy.objects == clean.objects
    assert _entries(tmp_path / "noisy.TXT") == _entries(tmp_path / "clean.TXT")


def test_a_burst_of_noise_fails_the_backup_clearly_and_the_link_recovers(noisy_serial, tmp_path):
    relay, connection = noisy_serial
    drive, path = connection.drive(2), tmp_path / "DRIVEPAR.TXT"

    def burst(event: dict) -> None:
        if event["done"] > 0 and not relay_burst.is_set():
            relay_burst.set()
            relay.corrupt(100_000)  # every answer for the next while

    relay_burst = threading.Event()
    with pytest.raises(BackupError, match=r"no file written.*no SDO response"):
        backup_file(drive, path, progress=burst)
    assert not path.exists()
    relay.quiet()  # the line is clean again
    assert backup_file(drive, path).objects > 300


def test_a_link_cut_during_a_sequence_restore_says_so_and_the_restore_can_be_rerun(
    socketcand_bus, socketcand, tmp_path
):
    drive = socketcand_bus.drive(3)
    path = tmp_path / "SEQUENCE.TXT"
    table = SequenceTable({number: Sequence.of(SequenceType.POS, Pos=1000 * number, Speed=500) for number in range(4)})
    write_sequence_file(path, table)

    def cut(event: dict) -> None:
        if event["done"] > 0 and socketcand.server is not None:
            socketcand.cut()

    try:
        with slow_drives(socketcand.network):
            result = restore_file(drive, path, FileKind.SEQUENCE, progress=cut, store=False)
        assert not result.ok and "lost" in result.error and result.stored == ""
    finally:
        if socketcand.server is None:
            socketcand.restore()
    assert socketcand_bus.link.wait_connected(5.0)
    assert restore_file(drive, path, FileKind.SEQUENCE, store=False).ok
