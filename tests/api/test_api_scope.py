"""The oscilloscope's REST routes on the simulated bus: a capture as a job with progress events, refusals before
arming (422 with the reason), force and stop, exports, and captures saved in a project under their axis."""

from __future__ import annotations

import time

import pytest
from fastapi.testclient import TestClient
from tests.support.access import admin_app, api_client
from tests.support.jobs_api import finished

from servostudio.services.scope import capture_csv
from servostudio.services.settings import Settings

SCOPE = "/api/buses/sim/nodes/1/scope"
IMMEDIATE = {"channels": ["0x6064,0", "statusword"], "samples": 100}
NEVER = {"channels": ["0x6064,0"], "samples": 50, "trigger": {"source": "0x6064,0", "edge": "rising", "level": 1e9}}


@pytest.fixture(scope="module")
def client(tmp_path_factory, sim_opener):
    root = tmp_path_factory.mktemp("api-scope")
    app = admin_app(Settings(projects_dir=root / "store", static_dir=root / "no-ui", buses=["sim"]), root / "data")
    with api_client(app) as test_client:
        sim_opener(app.state.server.connections)
        yield test_client


def wait_status(client: TestClient, wanted: str) -> dict:
    deadline = time.monotonic() + 10
    while (status := client.get(f"{SCOPE}/status").json())["status"] != wanted:
        assert time.monotonic() < deadline, status
        time.sleep(0.02)
    return status


def test_the_recorder_its_limits_and_presets(client):
    info = client.get(SCOPE).json()
    assert (info["channels"], info["capacity"], info["base_period_ns"]) == (4, 32768, 250_000)
    assert [preset["key"] for preset in info["presets"]] == [
        "speed-step",
        "following-error",
        "current-loop",
        "io-timing",
    ]
    plan = client.post(f"{SCOPE}/check", json={"channels": ["0x6041", "0x6064"], "period_us": 1000}).json()
    assert (plan["samples"], plan["multiplier"], plan["record_size"], plan["bytes"]) == (2048, 4, 6, 12288)


def test_a_capture_job_reports_its_progress_and_keeps_the_capture(client):
    events: list[dict] = []
    client.app.state.server.connections.events.add_listener(events.append)
    started = client.post(f"{SCOPE}/captures", json=IMMEDIATE)
    assert started.status_code == 202 and started.json()["operation"] == "scope"
    job = finished(client, started.json()["id"])
    assert job["state"] == "done" and job["result"]["captures"] == 1, job
    capture_id = job["result"]["capture"]
    made = client.get(f"{SCOPE}/captures/{capture_id}").json()
    assert made["samples"] == 100 and made["trigger_index"] == 0 and made["period_ns"] == 250_000
    assert [channel["key"] for channel in made["channels"]] == ["0x6064,0", "0x6041,0"]
    assert made["drive"]["device"] == "xtrapulspac" and made["source"] == "recorder"
    stages = [event["stage"] for event in events if event.get("job") == job["id"] and event["type"] == "progress"]
    assert stages[0] == "armed" and "uploading" in stages and stages[-1] == "captured"

    csv = client.get(f"{SCOPE}/captures/{capture_id}/csv")
    kept = client.app.state.server.scope.get(capture_id)
    assert csv.headers["content-type"].startswith("text/csv") and csv.text == capture_csv(kept)  # one implementation
    assert "attachment" in csv.headers["content-disposition"]
    page = client.get(f"{SCOPE}/captures/{capture_id}/html")
    assert page.headers["content-type"].startswith("text/html") and "scattergl" in page.text
    assert client.get(f"/api/buses/sim/nodes/2/scope/captures/{capture_id}").status_code == 404  # another node's id
    assert client.get(f"{SCOPE}/captures/nothing").status_code == 404


@pytest.mark.parametrize(
    ("body", "reason"),
    [
        ({"channels": ["0x6041"], "period_us": 300}, "multiple of its 250 µs base period"),
        ({"channels": ["0x306C"]}, "cannot be recorded"),
        ({"channels": ["0x6064", "0x606C", "0x6062", "0x60F4"], "samples": 4096}, "hold 2048 samples"),
        ({"channels": ["0x6041"], "trigger": {"source": "0x6041", "level": 70000}}, "can never fire rising"),
    ],
)
def test_what_the_drive_cannot_capture_is_refused_before_arming(client, body, reason):
    answer = client.post(f"{SCOPE}/captures", json=body)
    assert answer.status_code == 422 and answer.json()["kind"] == "invalid_input"
    assert reason in answer.json()["detail"] and answer.json()["error"] == "CaptureRefused"
    assert client.get(f"{SCOPE}/status").json()["job"] is None


def test_force_while_waiting_and_stop_of_a_normal_mode_job(client):
    events: list[dict] = []
    client.app.state.server.connections.events.add_listener(events.append)
    job = client.post(f"{SCOPE}/captures", json={**NEVER, "mode": "normal"}).json()
    wait_status(client, "waiting")
    assert client.post(f"{SCOPE}/captures", json=IMMEDIATE).status_code == 409  # one capture job per node
    assert client.post(f"{SCOPE}/force").status_code == 200
    deadline = time.monotonic() + 20
    while not any(event.get("job") == job["id"] and event.get("stage") == "captured" for event in events):
        assert time.monotonic() < deadline, events[-3:]
        time.sleep(0.05)
    wait_status(client, "waiting")  # normal mode: armed again for the next trigger
    stopped = client.post(f"{SCOPE}/stop").json()
    assert stopped["status"] == "idle" and stopped["job"] is None  # the job ended before the answer
    ended = client.get(f"/api/jobs/{job['id']}").json()
    assert ended["state"] == "cancelled" and ended["result"]["captures"] >= 1  # what it made before the stop


def test_saved_captures_of_an_axis(client):
    assert client.post("/api/projects", json={"name": "s"}).status_code == 201
    assert client.post("/api/projects/s/scan", json={"bus": "sim"}).status_code == 200
    capture_id = finished(client, client.post(f"{SCOPE}/captures", json=IMMEDIATE).json()["id"])["result"]["capture"]
    base = "/api/projects/s/axes/Axis1/captures"
    saved = client.post(base, json={"capture": capture_id, "name": "first"})
    assert saved.status_code == 201 and saved.json()["name"] == "first"
    assert client.post(base, json={"capture": capture_id, "name": "FIRST"}).status_code == 409
    listed = client.get(base).json()
    assert [(item["name"], item["samples"], item["channels"]) for item in listed] == [
        ("first", 100, ["0x6064,0", "0x6041,0"])
    ]
    opened = client.get(f"{base}/first").json()
    assert opened["values"] == client.get(f"{SCOPE}/captures/{capture_id}").json()["values"]
    assert client.get(f"{base}/first/csv").text == client.get(f"{SCOPE}/captures/{capture_id}/csv").text
    assert client.get(f"{base}/first/html").status_code == 200
    assert client.get(f"{base}/other").status_code == 404
    assert client.delete(f"{base}/first").status_code == 204
    assert client.get(base).json() == []


def test_a_drive_without_recorder_captures_through_tpdos_and_states_rate_and_bus_load(tmp_path, sim_opener):
    app = admin_app(Settings(projects_dir=tmp_path, static_dir=tmp_path / "no-ui", buses=[]), tmp_path / "data")
    with api_client(app) as client:
        sim_opener(app.state.server.connections, "sim:1:cd1k")
        bus = app.state.server.connections.list()[0].id
        scope = f"/api/buses/{bus}/nodes/1/scope"
        info = client.get(scope).json()
        assert (info["source"], info["capacity"], info["base_period_ns"]) == ("tpdo", None, 1_000_000)
        definition = {"channels": ["0x6064,0", "0x6041,0"], "period_us": 1000, "samples": 100}
        plan = client.post(f"{scope}/check", json=definition).json()
        assert plan["source"] == "tpdo" and plan["multiplier"] is None
        stream = plan["stream"]
        assert stream["rate_hz"] == 1000 and stream["frames_per_s"] == 2000 and stream["bitrate_assumed"] is True
        assert stream["bus_load"] == pytest.approx((47 + 48 + (34 + 48 - 1) // 4 + 55) / 1000)  # 6 bytes + SYNC
        refused = client.post(f"{scope}/check", json={**definition, "period_us": 250})
        assert refused.status_code == 422 and "every 1000 µs at the fastest" in refused.json()["detail"]
        job = finished(client, client.post(f"{scope}/captures", json=definition).json()["id"])
        assert job["state"] == "done", job
        made = client.get(f"{scope}/captures/{job['result']['capture']}").json()
        assert made["source"] == "tpdo" and made["samples"] == 100 and made["alignment_ns"] is not None
        assert "# source: tpdo" in client.get(f"{scope}/captures/{job['result']['capture']}/csv").text
        assert client.get(f"{scope}/status").json() == {"status": "idle", "counter": 0, "job": None}
