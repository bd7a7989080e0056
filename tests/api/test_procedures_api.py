"""The procedures over REST on the server's simulated drives: the list with preconditions, refusals before anything
is written (404, 422, 409), a job with progress events whose result is saved under the project's axis, abort by
cancelling the job, undo of an auto-tuning's gains."""

from __future__ import annotations

import time

import pytest
from tests.support.access import admin_app, api_client
from tests.support.jobs_api import armed, finished

from servostudio.api.app import Settings

NODE = "/api/buses/sim/nodes/1"


@pytest.fixture(scope="module")
def app(tmp_path_factory):
    root = tmp_path_factory.mktemp("procedures")
    return admin_app(Settings(projects_dir=root / "projects", static_dir=root / "no-ui", buses=("sim",)), root / "data")


@pytest.fixture
def client(app):
    with api_client(app) as client:
        yield client


def test_the_list_names_every_procedure_with_its_preconditions(client):
    listed = client.get(f"{NODE}/procedures").json()
    assert [item["name"] for item in listed] == [
        "auto_phasing", "motor_phasing", "current_loop", "current_limits", "auto_tuning",
    ]  # fmt: skip
    phasing = listed[0]
    assert phasing["moves"] is True and phasing["ready"] is True
    assert {item["name"] for item in phasing["preconditions"]} >= {"disabled", "no_fault", "no_limit_switch", "dc_bus"}


def test_refusals_come_before_anything_is_written(client):
    assert client.post(f"{NODE}/procedures/sseq", json={}).status_code == 404
    bad = client.post(f"{NODE}/procedures/auto_tuning", json={"options": {"bandwidth": 60}})
    assert bad.status_code == 422 and "50, 75, 100" in bad.json()["detail"]
    unarmed = client.post(f"{NODE}/procedures/auto_phasing", json={})
    assert unarmed.status_code == 409 and unarmed.json()["kind"] == "refused_for_safety"
    braked = None
    with armed(client) as (_, header):
        braked = client.post(f"{NODE}/procedures/auto_tuning", json={}, headers=header)
    assert braked.status_code == 409 and "brake" in braked.json()["detail"]
    assert client.get(f"{NODE}/objects/0x3426").json()["raw"] == 0


def test_a_current_loop_job_is_saved_under_the_axis(client):
    project = {"name": "bench", "buses": [{"name": "sim", "interface": "sim"}]}
    assert client.post("/api/projects", json=project).status_code == 201
    axis = {"name": "x", "device": "xtrapulspac", "node_id": 1, "bus": "sim"}
    assert client.post("/api/projects/bench/axes", json=axis).status_code == 201
    with armed(client) as (socket, header):
        started = client.post(
            f"{NODE}/procedures/current_loop", json={"options": {"regulator": "high"}, "project": "bench", "axis": "x"},
            headers=header,
        )  # fmt: skip
        assert started.status_code == 202 and started.json()["operation"] == "procedure:current_loop"
        job = finished(client, started.json()["id"])
        phases = []
        while True:
            event = socket.receive_json()
            if event["type"] == "job":
                break
            phases.append(event["phase"])
    assert job["state"] == "done", job
    result = job["result"]
    assert result["status"] == "done" and set(result["gains"]["after"]) == {
        "kp_current_q", "ki_current_q", "kp_current_d", "ki_current_d",
    }  # fmt: skip
    assert phases[0] == "preconditions" and phases[-1] == "done"
    saved = client.get("/api/projects/bench/axes/x/procedures").json()
    assert saved and saved[0]["procedure"] == "current_loop" and result["saved"].endswith(saved[0]["file"])


def test_cancelling_the_job_aborts_the_phasing(client):
    before = client.get(f"{NODE}/objects/0x3410,3").json()["raw"]
    with armed(client) as (_, header):
        started = client.post(f"{NODE}/procedures/auto_phasing", json={}, headers=header).json()
        deadline = time.monotonic() + 10
        while client.get(f"{NODE}/objects/0x3413").json()["raw"] != 2 and time.monotonic() < deadline:
            time.sleep(0.05)
        client.post(f"/api/jobs/{started['id']}/cancel")
        job = finished(client, started["id"])
    assert job["state"] == "cancelled" and job["result"]["status"] == "aborted"
    assert client.get(f"{NODE}/objects/0x3413").json()["raw"] == 3
    assert client.get(f"{NODE}/objects/0x3410,3").json()["raw"] == before


def test_undo_is_checked_completely_before_any_write(client):
    kp = client.get(f"{NODE}/objects/0x60F9,2").json()["raw"]
    foreign = client.post(f"{NODE}/procedures/auto_tuning/undo", json={"gains": {"kp_speed": 1, "controlword": 15}})
    assert foreign.status_code == 422 and "controlword" in foreign.json()["detail"]
    assert client.get(f"{NODE}/objects/0x60F9,2").json()["raw"] == kp
    undone = client.post(f"{NODE}/procedures/auto_tuning/undo", json={"gains": {"kp_speed": kp + 1}})
    assert undone.status_code == 200 and undone.json()["gains"] == {"kp_speed": kp + 1}
    client.post(f"{NODE}/procedures/auto_tuning/undo", json={"gains": {"kp_speed": kp}})
