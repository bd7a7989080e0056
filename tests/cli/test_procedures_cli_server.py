"""The procedure commands through ``--server``: the command is a live client of the server (it arms the axis for its
duration, the server runs the procedure as a job), the answer is the job's result, the axis is released after."""

from __future__ import annotations

import json

import httpx
import pytest
from tests.support.commands import servostudio
from tests.support.motion_timing import InProcessServer


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    running = InProcessServer(tmp_path_factory.mktemp("procedures-cli"))
    yield running
    running.close()


def test_autophase_through_the_server(server):
    done = servostudio("--server", server.url, "autophase", "--bus", "sim", "--node", "3", "--yes")
    assert done.returncode == 0, done.stderr
    result = json.loads(done.stdout)
    assert result["status"] == "done" and result["pole_pairs"] == 4 and result["phase_order"] == 0x5555
    assert result["verification"]["passed"] is True
    assert httpx.get(f"{server.url}/api/buses/sim/nodes/3/objects/0x3413").json()["raw"] == 5
    assert httpx.get(f"{server.url}/api/control").json() == []  # released again


def test_refusals_through_the_server_keep_their_exit_code(server):
    refused = servostudio(
        "autotune", "--server", server.url, "--bus", "sim", "--node", "3", "--bandwidth", "50", "--yes"
    )
    assert refused.returncode == 3 and "brake" in refused.stderr
    unknown = servostudio("currentloop", "--server", server.url, "--bus", "nowhere", "--node", "3", "--yes")
    assert unknown.returncode == 4


def plant_of(server, node: int):
    with server.network.lock:
        return server.network.node(node).behaviour.plant


def test_motorphase_through_the_server_finds_the_offset(server):
    plant = plant_of(server, 3)
    done = servostudio("motorphase", "--server", server.url, "--bus", "sim", "--node", "3", "--yes")
    assert done.returncode == 0, done.stderr
    result = json.loads(done.stdout)
    assert result["status"] == "done" and result["procedure"] == "motor_phasing"
    error = (result["sensor_offset"] - plant.sensor_offset) % 65536
    assert min(error, 65536 - error) <= 65536 * 2 / 360  # within 2 electrical degrees of the true offset


def test_autotune_through_the_server_prints_the_pinned_result(server):
    node = f"{server.url}/api/buses/sim/nodes/3"
    for key, value in (("0x60FE,2", 1), ("0x60FE,1", 0)):  # the brake released by manual brake control
        assert httpx.put(f"{node}/objects/{key}", json={"value": value}, timeout=15).is_success
    plant = plant_of(server, 3)
    done = servostudio(
        "--server", server.url, "autotune", "--bus", "sim", "--node", "3", "--bandwidth", "100",
        "--filter", "standard", "--speed-filter", "auto", "--mode", "min-overshoot", "--yes",
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    result = json.loads(done.stdout)
    assert result["status"] == "done"
    identified = result["identified"]
    assert {"inertia_kgm2", "viscous_friction_nms_per_rad", "coulomb_friction_nm", "load_torque_nm"} <= set(identified)
    assert identified["inertia_kgm2"] == pytest.approx(plant.total_inertia, rel=0.10)
    assert identified["viscous_friction_nms_per_rad"] == pytest.approx(plant.viscous_friction, rel=0.25)
    gains = result["gains"]
    assert set(gains["before"]) == set(gains["after"]) >= {"kp_speed", "ki_speed", "kp_position"}
    assert httpx.get(f"{node}/objects/0x60F9,2", timeout=15).json()["raw"] == gains["after"]["kp_speed"]
    assert gains["after"]["kf_position"] == 0  # minimum overshoot: no position feed-forward
    chosen = {key: str(value) for key, value in result["options"].items()}
    assert chosen == {"bandwidth": "100", "filter": "standard", "speed_filter": "auto", "mode": "min-overshoot"}
