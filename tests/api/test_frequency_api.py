"""The frequency response over REST on the server's simulated drive: refusals before anything is written (422, 409,
404), then a job whose result is the result dict of the contract (issue #16), saved under the project's axis and
listed there.  The measurement's accuracy is judged in tests/services/frequency (hidden plants, SYNC-locked drive);
here the server's own simulator (as ``make run`` has it) locks its drives to the measurement's SYNC
(sim/sync_lock.py)."""

from __future__ import annotations

import pytest
from tests.support.access import admin_app, api_client
from tests.support.jobs_api import armed, finished

from servostudio.api.app import Settings

NODE = "/api/buses/sim/nodes/1"
ROUTE = f"{NODE}/frequency-response"
QUICK = {"loop": "plant", "periods": 2, "base_speed_rad_s": 10.0, "position_window": 20.0}


@pytest.fixture(scope="module")
def app(tmp_path_factory):
    root = tmp_path_factory.mktemp("frequency")
    return admin_app(Settings(projects_dir=root / "projects", static_dir=root / "no-ui", buses=("sim",)), root / "data")


@pytest.fixture
def client(app):
    with api_client(app) as client:
        yield client


def test_refusals_come_before_anything_is_written(client):
    unarmed = client.post(ROUTE, json=QUICK)
    assert unarmed.status_code == 409 and unarmed.json()["kind"] == "refused_for_safety"
    with armed(client) as (_, header):
        beyond = client.post(ROUTE, json={**QUICK, "to_hz": 900}, headers=header)
        assert beyond.status_code == 422 and "Hz" in beyond.json()["detail"]
        unknown = client.post(ROUTE, json={**QUICK, "project": "nowhere", "axis": "x"}, headers=header)
        assert unknown.status_code == 404
        assert client.post(ROUTE, json={**QUICK, "loop": "open"}, headers=header).status_code == 422
    assert client.get(f"{NODE}/objects/0x1603,0").json()["raw"] == 0  # no RPDO borrowed


def test_a_measurement_job_is_saved_under_the_axis(client):
    project = {"name": "bench", "buses": [{"name": "sim", "interface": "sim"}]}
    assert client.post("/api/projects", json=project).status_code == 201
    axis = {"name": "x", "device": "xtrapulspac", "node_id": 1, "bus": "sim"}
    assert client.post("/api/projects/bench/axes", json=axis).status_code == 201
    with armed(client) as (socket, header):
        started = client.post(ROUTE, json={**QUICK, "project": "bench", "axis": "x"}, headers=header)
        assert started.status_code == 202 and started.json()["operation"] == "frequency-response"
        job = finished(client, started.json()["id"])
        stages = []
        while True:
            event = socket.receive_json()
            if event["type"] == "job":
                break
            stages.append(event["stage"])
    assert job["state"] == "done", job
    result = job["result"]
    assert {"settling", "recording", "done"} <= set(stages)
    assert result["kind"] == "frequency_response" and result["loop"] == "plant" and result["device"] == "xtrapulspac"
    assert result["aborted"] is None and result["excitation"]["source"] == "recorder"
    assert len(result["points"]) == result["excitation"]["points"] > 40
    assert set(result["points"][0]) == {"freq_hz", "magnitude_db", "phase_deg", "coherence"}
    assert set(result["markers"]) == {
        "bandwidth_hz",
        "gain_margin_db",
        "phase_margin_deg",
        "resonance_hz",
        "antiresonance_hz",
    }
    assert result["plant_fit"]["inertia_kgm2"] > 0 and result["gains"]["kp_a_per_rad_s"] > 0
    saved = client.get("/api/projects/bench/axes/x/frequency").json()
    assert [item["name"] for item in saved] == [result["saved"]]
    assert client.get(f"{NODE}/objects/0x1603,0").json()["raw"] == 0  # the RPDO is back
    assert client.get(f"{NODE}/objects/0x6041").json()["raw"] & 0x6F != 0x27  # disabled again
