"""Tool-side identification over REST on the server's simulated encoTRive (``sim:1:encotrive``): refusals before
anything is written (422, 409), then a job whose result carries the pinned ``identified`` keys, judged against the
simulated axis's true plant; then one with a bandwidth, which writes the encoTRive's inertia setting Θi and verifies
it by a step (the bandwidth also measured on the true plant's shaft)."""

from __future__ import annotations

import pytest
from tests.support.access import admin_app, api_client
from tests.support.jobs_api import armed, finished
from tests.support.shaft_step import encotrive_bandwidth

from servostudio.api.app import Settings
from servostudio.sim.plant import Plant

NODE = "/api/buses/sim/nodes/1"
PATH = f"{NODE}/identification"


@pytest.fixture(scope="module")
def app(tmp_path_factory):
    root = tmp_path_factory.mktemp("identification")
    settings = Settings(projects_dir=root / "projects", static_dir=root / "no-ui", buses=("sim:1:encotrive",))
    return admin_app(settings, root / "data")


@pytest.fixture
def client(app):
    with api_client(app) as client:
        yield client


def enabled(client) -> bool:
    return client.get(f"{NODE}/objects/0x6041").json()["raw"] & 0x6F == 0x27


def test_refusals_come_before_anything_is_written(client):
    unarmed = client.post(PATH, json={})
    assert unarmed.status_code == 409 and unarmed.json()["kind"] == "refused_for_safety"
    with armed(client) as (_, header):
        small = client.post(PATH, json={"options": {"position_window_rev": 1}}, headers=header)
        assert small.status_code == 422 and "beyond the position window" in small.json()["detail"]
        typo = client.post(PATH, json={"options": {"spin": 1}}, headers=header)
        assert typo.status_code == 422
    assert not enabled(client)  # nothing was started


def test_an_identification_job_ends_with_the_pinned_result(client):
    plant = Plant.commissioned()
    limit = client.get(f"{NODE}/objects/0x6073").json()["raw"]
    with armed(client) as (socket, header):
        started = client.post(PATH, json={"options": {"cycles": 1}}, headers=header)
        assert started.status_code == 202, started.text
        job = finished(client, started.json()["id"])
        progress = socket.receive_json()
    assert job["state"] == "done", job
    assert progress["type"] == "progress" and progress["operation"] == "identification"
    identified = job["result"]["identified"]
    assert set(identified) == {"inertia_kgm2", "viscous_friction_nms_per_rad", "coulomb_friction_nm",
                               "load_torque_nm", "residual", "inertia_ratio"}  # fmt: skip
    assert identified["inertia_kgm2"] == pytest.approx(plant.total_inertia, rel=0.10)
    assert identified["coulomb_friction_nm"] == pytest.approx(plant.coulomb_friction, rel=0.15)
    assert not enabled(client) and client.get(f"{NODE}/objects/0x6073").json()["raw"] == limit  # as it was


def test_a_tuning_job_writes_the_inertia_setting_of_the_bandwidth(client):
    factory = client.get(f"{NODE}/objects/0x2F02,8").json()["raw"]
    with armed(client) as (_, header):
        body = {"options": {"cycles": 1}, "bandwidth_hz": 50}
        started = client.post(PATH, json=body, headers=header)
        assert started.status_code == 202, started.text
        job = finished(client, started.json()["id"])
    assert job["state"] == "done", job
    tuning = job["result"]["tuning"]
    written = client.get(f"{NODE}/objects/0x2F02,8").json()["raw"]
    assert written != factory and tuning["gains"]["after"]["inertia_setting_kgm2"] == pytest.approx(written * 1e-7)
    assert tuning["verification"]["speed_step"]["bandwidth_hz"] > 0  # by TPDOs (docs/identification.md)
    assert encotrive_bandwidth(Plant.commissioned(), written) == pytest.approx(50, rel=0.20)  # the true shaft
    loop = client.get(f"{NODE}/speed-loop").json()  # the derived gains, and the one key a PUT takes
    assert loop["writable"] == ["inertia_setting_kgm2"]
    assert loop["inertia_setting_kgm2"] == pytest.approx(written * 1e-7)
    assert not enabled(client)
