"""The procedure commands through ``--server``: the command is a live client of the server (it arms the axis for its
duration, the server runs the procedure as a job), the answer is the job's result, the axis is released after."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import httpx
import pytest
from tests.support.motion_timing import InProcessServer


def servostudio(*args: str, timeout: float = 120) -> subprocess.CompletedProcess:
    command = [sys.executable, "-m", "servostudio", *args]
    return subprocess.run(command, capture_output=True, text=True, timeout=timeout, env=dict(os.environ))


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
