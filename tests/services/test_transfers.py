"""Backup and restore as the server runs them (`services.transfers`, `services.backup.restore_drive`): a job per bus,
a result per node and a state from them all, refusals of the request itself before any job starts, and uploads
taken as the drive's own 8-bit files."""

from __future__ import annotations

import time

import pytest

from servostudio.errors import InvalidInput
from servostudio.services.bus import ConnectionManager, JobRegistry
from servostudio.services.transfers import DirectoryRefused, file_kind, start_backup, start_restore, upload


@pytest.fixture(scope="module")
def bus(sim_opener):
    manager = ConnectionManager()
    sim_opener(manager)
    yield manager.get("sim")
    manager.close_all()


def finished(job):
    deadline = time.monotonic() + 60
    while job.state == "running" and time.monotonic() < deadline:
        time.sleep(0.05)
    return job


def test_backup_then_restore_per_node(bus, tmp_path):
    jobs = JobRegistry(bus.events)
    backup = finished(start_backup(jobs, bus, [tmp_path], str(tmp_path), [1], ["DRIVEPAR.TXT"]))
    assert backup.state == "done" and [item["kind"] for item in backup.result["1"]] == ["DRIVEPAR.TXT"]
    restore = finished(start_restore(jobs, bus, [tmp_path], str(tmp_path), [1], None, store=False))
    assert restore.state == "done" and not restore.error
    assert [item["ok"] for item in restore.result["1"]] == [True]


def test_a_job_with_some_nodes_failed_is_partial_and_names_them(bus, tmp_path):
    jobs = JobRegistry(bus.events)
    finished(start_backup(jobs, bus, [tmp_path], str(tmp_path), [1], ["DRIVEPAR.TXT"]))
    restore = finished(start_restore(jobs, bus, [tmp_path], str(tmp_path), [1, 2], None, store=False))
    assert restore.state == "partial"
    assert [item["ok"] for item in restore.result["1"]] == [True]
    assert "node2/: none of DRIVEPAR.TXT, USER_PAR.TXT, SEQUENCE.TXT for node 2" in restore.result["2"]["error"]
    assert restore.error.startswith("1 of 2 failed: node 2:")


def test_a_job_whose_every_node_failed_is_failed(bus, tmp_path):
    jobs = JobRegistry(bus.events)
    restore = finished(start_restore(jobs, bus, [tmp_path], str(tmp_path), [1, 2], None, store=False))
    assert restore.state == "failed"
    assert restore.error.startswith("2 of 2 failed: node 1:")
    assert set(restore.result) == {"1", "2"}  # the per-node results are kept


def test_refusals_come_before_any_job(bus, tmp_path):
    jobs = JobRegistry(bus.events)
    with pytest.raises(InvalidInput, match="files must be among"):
        start_backup(jobs, bus, [tmp_path], str(tmp_path), [1], ["NOTES.TXT"])
    assert jobs.list() == []


@pytest.mark.parametrize("directory", ["/etc", "{root}/../elsewhere", "{root}/link/inside"])
def test_a_directory_outside_the_allowed_roots_is_refused_without_naming_it(bus, tmp_path, directory):
    root = tmp_path / "store"
    root.mkdir()
    (root / "link").symlink_to(tmp_path)  # a link inside the store pointing out of it
    jobs = JobRegistry(bus.events)
    named = directory.format(root=root)
    with pytest.raises(DirectoryRefused) as refused:
        start_backup(jobs, bus, [root], named, [1], None)
    assert str(tmp_path) not in str(refused.value) and "/etc" not in str(refused.value)
    assert jobs.list() == []


def test_latin1_and_empty_uploads_are_valid_drive_files(bus):
    drive = bus.drive(1)
    text = "; réglage usine\n0x6065,0=4000 ; fenêtre\n"
    accented = upload(drive, file_kind("drivepar.txt"), text.encode("latin-1"), store=False)
    assert accented.ok and accented.as_dict()["counts"] == {"verified": 1}
    empty = upload(drive, file_kind("DRIVEPAR.TXT"), b"", store=False)
    assert empty.ok and empty.outcomes == [] and not empty.error


def test_an_invalid_upload_names_the_file_by_its_kind_and_no_server_path(bus):
    with pytest.raises(InvalidInput) as refused:
        upload(bus.drive(1), file_kind("USER_PAR.TXT"), b"; fine\n0x6065,0=banana\n", store=False)
    assert str(refused.value).startswith("USER_PAR.TXT:2: ")
    assert "/" not in str(refused.value).split(" — ")[0]
