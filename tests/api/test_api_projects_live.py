"""The live project routes through the FastAPI app, on the server's own embedded simulated drives."""

from __future__ import annotations

import time

import pytest
from fastapi.testclient import TestClient
from tests.support.access import admin_app, api_client

from servostudio.api.app import Settings


@pytest.fixture(scope="module")
def client(tmp_path_factory, sim_opener):
    root = tmp_path_factory.mktemp("api-store")
    app = admin_app(Settings(projects_dir=root / "store", static_dir=root / "no-ui", buses=["sim"]), root / "data")
    with api_client(app) as test_client:
        sim_opener(app.state.server.connections)
        yield test_client


def wait_for(client: TestClient, job: dict) -> dict:
    deadline = time.monotonic() + 60
    while job["state"] == "running":
        assert time.monotonic() < deadline, job
        time.sleep(0.05)
        job = client.get(f"/api/jobs/{job['id']}").json()
    return job


def test_scan_commission_compare_take_over_rest(client):
    events: list[dict] = []
    client.app.state.server.connections.events.add_listener(events.append)
    assert client.post("/api/projects", json={"name": "r"}).status_code == 201
    scanned = client.post("/api/projects/r/scan", json={"bus": "sim"}).json()
    assert [(node["node_id"], node["status"]) for node in scanned["nodes"]] == [
        (1, "added"),
        (2, "added"),
        (3, "added"),
    ]
    assert [axis["name"] for axis in scanned["project"]["axes"]] == ["Axis1", "Axis2", "Axis3"]

    started = client.post("/api/projects/r/commission", json={"direction": "check"})
    assert started.status_code == 202 and started.json()["operation"] == "commission-check"
    job = wait_for(client, started.json())
    assert job["state"] == "done" and job["result"]["ok"], job
    assert [(axis["axis"], axis["status"]) for axis in job["result"]["axes"]] == [
        ("Axis1", "ok"),
        ("Axis2", "ok"),
        ("Axis3", "ok"),
    ]
    assert any(event.get("job") == job["id"] and event.get("step") == "identified" for event in events)

    bus = client.app.state.server.connections.list()[0].id
    assert client.put(f"/api/buses/{bus}/nodes/1/objects/0x6083", json={"value": 131072}).status_code == 200
    answer = client.get(
        "/api/projects/r/axes/Axis1/compare",
        params={"drive": True, "only_differences": True, "group": "Profile Position Mode"},
    )
    assert answer.status_code == 200 and answer.json()["columns"] == ["drive", "project", "default"]
    rows = {row["index"]: row["values"] for row in answer.json()["rows"]}
    assert rows[0x6083] == {"drive": 131072, "project": 65536, "default": 65536}
    taken = client.post("/api/projects/r/axes/Axis1/take-from-drive", json={"addresses": ["0x6083"]}).json()
    assert [(row["index"], row["value"], row["file"]) for row in taken["parameters"]] == [
        (0x6083, 131072, "DRIVEPAR.TXT")
    ]
    assert client.get("/api/projects/r/axes/Axis1/parameters/0x6083").json()["value"] == 131072


def test_refusals_over_rest(client):
    refused = client.post("/api/projects/r/axes/Axis2/write-to-drive", json={"addresses": ["0x6065"]})
    assert refused.status_code == 422 and refused.json()["error"] == "ParameterRefused"
    assert (
        client.post("/api/projects", json={"name": "wrong", "buses": [{"name": "sim", "interface": "sim"}]}).status_code
        == 201
    )
    assert (
        client.post(
            "/api/projects/wrong/axes", json={"name": "K", "device": "cd1k", "node_id": 2, "bus": "sim"}
        ).status_code
        == 201
    )
    mismatch = client.get("/api/projects/wrong/axes/K/compare", params={"drive": True})
    assert mismatch.status_code == 409 and mismatch.json()["error"] == "DriveMismatch"
    assert "expected device 'cd1k'" in mismatch.json()["detail"]
    job = wait_for(client, client.post("/api/projects/wrong/commission", json={}).json())
    assert job["state"] == "done" and not job["result"]["ok"]
    assert job["result"]["axes"][0]["status"] == "wrong_device"
    assert client.post("/api/projects/missing/commission", json={}).status_code == 404


def test_motor_selection_on_the_live_drive_over_rest(client):
    motor = {
        "reference": "M2",
        "description": "test motor",
        "source": "values chosen for the test",
        "motor_data": {"stall_current": 1800, "peak_current": 5400, "max_speed": 4500},
    }
    assert client.post("/api/motors", json=motor).status_code == 201
    chosen = client.post("/api/projects/r/axes/Axis2/motor", json={"reference": "M2", "drive": True})
    assert chosen.status_code == 200, chosen.text
    answer = chosen.json()
    changed = {(row["index"], row["subindex"]): row["value"] for row in answer["changed"]}
    bus = client.app.state.server.connections.list()[0].id
    on_drive = {
        key: client.get(f"/api/buses/{bus}/nodes/2/objects/{key}").json()["raw"]
        for key in ("0x6410,9", "0x6080", "0x6075", "0x6073")
    }
    assert on_drive["0x6410,9"] == 1800 and on_drive["0x6080"] == 4500
    assert {key: changed[int(key[2:6], 16), int(key.partition(",")[2] or 0)] for key in on_drive} == on_drive
    assert [axis["motor"] for axis in answer["project"]["axes"] if axis["name"] == "Axis2"] == ["M2"]
