"""``servostudio identify`` (issue #16 item 6, pinned): in-process on its own simulated encoTRive (the command is the
axis's live controller), and through ``--server`` (a live client; the server runs the job) on the server's
XtrapulsPac; JSON with auto-tuning's ``identified`` keys, judged against the simulated axis's true plant."""

from __future__ import annotations

import json

import httpx
import pytest
from tests.support.commands import run, servostudio
from tests.support.motion_timing import InProcessServer

from servostudio.sim.plant import Plant

PINNED = {"inertia_kgm2", "viscous_friction_nms_per_rad", "coulomb_friction_nm", "load_torque_nm", "residual",
          "inertia_ratio"}  # fmt: skip


@pytest.fixture(autouse=True)
def data_dir(tmp_path, monkeypatch):
    monkeypatch.setenv("SERVOSTUDIO_DATA_DIR", str(tmp_path / "data"))


def test_identify_prints_the_pinned_plant(capsys):
    code, out, err = run(capsys, "identify", "--bus", "sim:1:encotrive", "--node", "1", "--cycles", "1", "--yes")
    assert code == 0, err
    result = json.loads(out)
    assert result["status"] == "done" and set(result["identified"]) == PINNED
    assert result["identified"]["inertia_kgm2"] == pytest.approx(Plant.commissioned().total_inertia, rel=0.10)
    assert result["experiment"]["cycles"] == 1


def test_without_yes_or_with_a_profile_beyond_the_window_nothing_starts(capsys):
    code, out, err = run(capsys, "identify", "--bus", "sim:1:encotrive", "--node", "1")
    assert code == 3 and out == "" and "confirm with --yes" in err
    code, out, err = run(capsys, "identify", "--bus", "sim:1:encotrive", "--node", "1", "--window", "1", "--yes")
    assert code == 3 and out == "" and "beyond the position window" in err


def test_identify_through_the_server(tmp_path):
    server = InProcessServer(tmp_path)
    try:
        done = servostudio("--server", server.url, "identify", "--bus", "sim", "--node", "3", "--cycles", "1", "--yes")
        assert done.returncode == 0, done.stderr
        identified = json.loads(done.stdout)["identified"]
        plant = Plant.commissioned()
        assert identified["inertia_kgm2"] == pytest.approx(plant.total_inertia, rel=0.10)
        assert identified["inertia_ratio"] == pytest.approx(plant.total_inertia / plant.motor_inertia, rel=0.12)
        assert httpx.get(f"{server.url}/api/control").json() == []  # released again
    finally:
        server.close()
