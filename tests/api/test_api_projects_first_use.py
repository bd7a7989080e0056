"""Issue 14 over REST: compare counts only what a user can write or restore (read-only entries apart), and a backup
into the project keeps the previous revision restorable."""

from __future__ import annotations

import time

import pytest
from tests.support.access import admin_app, api_client

from servostudio.api.app import Settings

STATUSWORD, ERROR_REGISTER = (0x6041, 0), (0x1001, 0)


@pytest.fixture(scope="module")
def client(tmp_path_factory, sim_opener):
    root = tmp_path_factory.mktemp("api-first-use")
    app = admin_app(Settings(projects_dir=root / "store", static_dir=root / "no-ui", buses=["sim"]), root / "data")
    with api_client(app) as test_client:
        sim_opener(app.state.server.connections)
        assert test_client.post("/api/projects", json={"name": "r"}).status_code == 201
        assert test_client.post("/api/projects/r/scan", json={"bus": "sim"}).status_code == 200
        yield test_client


def _keys(rows: list[dict]) -> set[tuple[int, int]]:
    return {(row["index"], row["subindex"]) for row in rows}


def test_compare_with_the_drive_sets_read_only_entries_apart(client):
    plain = client.get("/api/projects/r/axes/Axis1/compare", params={"drive": True}).json()
    assert plain["read_only"] == [] and not _keys(plain["rows"]) & {STATUSWORD, ERROR_REGISTER}
    answer = client.get("/api/projects/r/axes/Axis1/compare", params={"drive": True, "read_only": True}).json()
    assert _keys(answer["rows"]) == _keys(plain["rows"])
    apart = {(row["index"], row["subindex"]): row for row in answer["read_only"]}
    assert {STATUSWORD, ERROR_REGISTER} <= set(apart)
    bus = client.app.state.server.connections.list()[0].id
    statusword = client.get(f"/api/buses/{bus}/nodes/1/objects/0x6041").json()["raw"]
    assert apart[STATUSWORD]["values"]["drive"] == statusword
    offline = client.get("/api/projects/r/axes/Axis1/compare", params={"read_only": True}).json()
    assert STATUSWORD in _keys(offline["read_only"]) and STATUSWORD not in _keys(offline["rows"])


def test_a_kept_backup_is_listed_and_restored(client):
    before = client.get("/api/projects/r").json()["revision"]
    assert client.get("/api/projects/r/revisions").json() == []
    written = client.put(
        "/api/projects/r/axes/Axis2/parameters", json={"values": {"0x60F9,2": 1234}, "keep_revision": True}
    ).json()
    kept = client.get("/api/projects/r/revisions").json()
    assert [item["revision"] for item in kept] == [before] and "Axis2" in kept[0]["reason"]
    stale = client.post(f"/api/projects/r/revisions/{before}/restore", json={"revision": before})
    assert stale.status_code == 409
    restored = client.post(f"/api/projects/r/revisions/{before}/restore", json={"revision": written["revision"]})
    assert restored.status_code == 200 and restored.json()["revision"] == before
    assert client.get("/api/projects/r/axes/Axis2/parameters/0x60F9,2").json()["file"] is None
    assert client.post("/api/projects/r/revisions/0123456789abcdef/restore", json={}).status_code == 404


def test_an_upload_of_the_drives_keeps_the_previous_revision(client):
    before = client.get("/api/projects/r").json()["revision"]
    job = client.post("/api/projects/r/commission", json={"direction": "upload", "axes": ["Axis3"]}).json()
    deadline = time.monotonic() + 60
    while job["state"] == "running":
        assert time.monotonic() < deadline, job
        time.sleep(0.05)
        job = client.get(f"/api/jobs/{job['id']}").json()
    assert job["state"] == "done" and job["result"]["ok"], job
    newest = client.get("/api/projects/r/revisions").json()[0]
    assert (newest["revision"], newest["reason"]) == (before, "upload of the drives into the project")
