"""Cancelling backup and restore jobs over REST, against the embedded simulated bus (``sim``).

The progress listener holds the bus reader thread at the first progress step, so the cancel request arrives while
the job is certainly mid-way; the job then has to report exactly which objects reached the drive.
"""

from __future__ import annotations

import threading
from pathlib import Path

import pytest
from fastapi.testclient import TestClient
from tests.support.access import admin_app, api_client
from tests.support.jobs_api import finished

from servostudio.api.app import Settings
from servostudio.formats.objectfile import ObjectEntry, read_object_file, write_object_file

WAIT = 20.0


@pytest.fixture(scope="module")
def app_client(tmp_path_factory):
    settings = Settings(export_dir=tmp_path_factory.getbasetemp())  # backups go to the tests' tmp_path
    app = admin_app(settings, tmp_path_factory.mktemp("data"))
    with api_client(app) as client:
        assert client.post("/api/buses", json={"spec": "sim"}).status_code == 201
        yield app, client


class _HoldAtFirstStep:
    """Event listener: at the first progress step with something done, hold the publishing (reader) thread until
    the test released it, and record every job event."""

    def __init__(self, operation: str) -> None:
        self.operation = operation
        self.reached, self.released = threading.Event(), threading.Event()
        self.job_events: list[dict] = []

    def __call__(self, event: dict) -> None:
        if event.get("type") == "job":
            self.job_events.append(event)
        if (
            event.get("type") == "progress"
            and event.get("operation") == self.operation
            and event.get("done", 0) > 0
            and not self.reached.is_set()
        ):
            self.reached.set()
            self.released.wait(WAIT)


def _cancel_at_first_step(
    app, client: TestClient, operation: str, url: str, body: dict
) -> tuple[dict, dict, _HoldAtFirstStep]:
    """Start a job, cancel it while its first progress step holds the bus reader, let it finish.
    Answers (job as started, job as finished, the listener with the job events)."""
    hub = app.state.server.connections.events
    hold = _HoldAtFirstStep(operation)
    hub.add_listener(hold)
    try:
        job = client.post(url, json=body).json()
        assert hold.reached.wait(WAIT), f"the {operation} never reported progress"
        answer = client.post(f"/api/jobs/{job['id']}/cancel")
        assert answer.status_code == 200 and answer.json()["state"] == "running"
        hold.released.set()
        return job, finished(client, job["id"], WAIT), hold
    finally:
        hold.released.set()
        hub.remove_listener(hold)


def _changed_file(app, client: TestClient, directory: Path) -> dict[tuple[int, int], tuple[int, int]]:
    """Back up node 1's DRIVEPAR.TXT, then rewrite it with every plain integer value raised by one.
    Answers {(index, sub): (value on the drive, value in the file)}."""
    job = client.post(
        "/api/buses/sim/backup", json={"directory": str(directory), "nodes": [1], "files": ["DRIVEPAR.TXT"]}
    ).json()
    assert finished(client, job["id"], WAIT)["state"] == "done"
    path = directory / "node1" / "DRIVEPAR.TXT"
    drive = app.state.server.connections.get("sim").drive(1)
    changed = {}
    for entry in read_object_file(path):
        variable = drive.variable((entry.index, entry.sub))
        if (
            isinstance(entry.value, int)
            and not variable.enum
            and variable.high is not None
            and entry.value + 1 <= variable.high
        ):
            changed[(entry.index, entry.sub)] = (entry.value, entry.value + 1)
    write_object_file(path, [ObjectEntry(index, sub, new) for (index, sub), (_, new) in changed.items()])
    assert len(changed) > 10
    return changed


def test_cancelled_restore_reports_exactly_what_was_written(app_client, tmp_path):
    app, client = app_client
    changed = _changed_file(app, client, tmp_path)
    job, finished, hold = _cancel_at_first_step(
        app,
        client,
        "restore",
        "/api/buses/sim/restore",
        {"directory": str(tmp_path), "nodes": [1], "files": ["DRIVEPAR.TXT"], "store": False},
    )
    assert finished["state"] == "cancelled"
    (result,) = finished["result"]["1"]
    assert result["cancelled"] is True and result["ok"] is False and result["stored"] == ""
    assert "cancelled" in result["error"] and "nothing was stored" in result["error"]
    counts = result["counts"]
    assert counts.get("written", 0) >= 1 and counts.get("not written", 0) >= 1
    assert sum(counts.values()) == len(changed)
    # The report is exact: every object it calls written holds the file's value, every other the old one.
    drive = app.state.server.connections.get("sim").drive(1)
    status = {row["label"]: row["status"] for row in result["objects"]}
    for key, (old, new) in changed.items():
        label = drive.variable(key).label
        expected = new if status[label] == "written" else old
        assert drive.read(key).raw == expected, (label, status[label])
    assert any(event["id"] == job["id"] and event["state"] == "cancelled" for event in hold.job_events)


def test_cancelled_backup_leaves_no_file(app_client, tmp_path):
    app, client = app_client
    _, finished, _ = _cancel_at_first_step(
        app, client, "backup", "/api/buses/sim/backup", {"directory": str(tmp_path), "nodes": [1, 2]}
    )
    assert finished["state"] == "cancelled"
    assert finished["result"] == {"1": [], "2": []}  # no file was complete when the cancel came
    assert [path for path in tmp_path.rglob("*") if path.is_file()] == []


def test_cancel_of_unknown_or_finished_job(app_client, tmp_path):
    _, client = app_client
    assert client.post("/api/jobs/job999999/cancel").status_code == 404
    job = client.post(
        "/api/buses/sim/backup", json={"directory": str(tmp_path), "nodes": [3], "files": ["DRIVEPAR.TXT"]}
    ).json()
    done = finished(client, job["id"], WAIT)
    assert done["state"] == "done"
    assert client.post(f"/api/jobs/{job['id']}/cancel").json()["state"] == "done"
    assert (tmp_path / "node3" / "DRIVEPAR.TXT").is_file()


def test_file_upload_as_a_job(app_client, tmp_path):
    app, client = app_client
    changed = _changed_file(app, client, tmp_path)
    text = (tmp_path / "node1" / "DRIVEPAR.TXT").read_text(encoding="latin-1")
    started = client.put(
        "/api/buses/sim/nodes/1/files/DRIVEPAR.TXT?job=true&store=false",
        content=text,
        headers={"Content-Type": "text/plain"},
    )
    assert started.status_code == 202 and started.json()["operation"] == "restore"
    restored = finished(client, started.json()["id"], WAIT)
    assert restored["state"] == "done"
    (result,) = restored["result"]["1"]
    assert result["file"] == "DRIVEPAR.TXT" and result["ok"] and result["counts"] == {"verified": len(changed)}
    drive = app.state.server.connections.get("sim").drive(1)
    assert all(drive.read(key).raw == new for key, (_, new) in changed.items())

    broken = client.put(
        "/api/buses/sim/nodes/1/files/DRIVEPAR.TXT?job=true",
        content="0x6081,0=oops\n",
        headers={"Content-Type": "text/plain"},
    )
    failed = finished(client, broken.json()["id"], WAIT)
    assert failed["state"] == "failed" and ":1:" in failed["error"] and "nothing was written" in failed["error"]
