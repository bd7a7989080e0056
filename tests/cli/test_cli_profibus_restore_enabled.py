"""`servostudio restore` of a TTAPAR.TXT refused while the TTA-PRO is enabled (docs/profibus.md §10): the drive
held in Operation enabled by `servostudio state … operation-enabled` (its armed controller, a process of its own)
on a server's bus, the restore through the same server refused with exit code 3 and the reason, and nothing
written — read back from the simulated slave (in this process, over its TCP stream)."""

from __future__ import annotations

import signal
import subprocess
import sys

import httpx
import pytest
from tests.support.motion_timing import InProcessServer, server_on_bus
from tests.support.profibus_line import ttapro_line

from servostudio.sim.drive.statemachine import State


@pytest.fixture(scope="module")
def line():
    with ttapro_line(5) as line:
        yield line


@pytest.fixture(scope="module")
def server(tmp_path_factory, line):
    with server_on_bus(tmp_path_factory.mktemp("cli-profibus-restore"), line.spec) as running:
        yield running


def servostudio(server: InProcessServer, *args: str) -> list[str]:
    return [sys.executable, "-m", "servostudio", "--server", server.url, *args, "--bus", "pb", "--node", "5"]


def test_a_restore_of_an_enabled_ttapro_is_refused_and_writes_nothing(server, line, tmp_path):
    memory = line.slaves[5].memory
    before = memory.get(730)
    upload = tmp_path / "TTAPAR.TXT"
    upload.write_text(f"721,0={memory.get(721)}\n730,0={before + 1}\n")
    holder = subprocess.Popen(
        servostudio(server, "state", "operation-enabled"), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )
    try:
        said = holder.stderr.readline()
        assert "holding" in said, said + holder.stderr.read()
        with line.line.lock:
            assert line.slaves[5].drive.device.state is State.OPERATION_ENABLED
        restore = subprocess.run(
            servostudio(server, "restore", "--in", str(upload)), capture_output=True, text=True, timeout=60
        )
        holder.send_signal(signal.SIGTERM)
        holder.communicate(timeout=30)
    finally:
        if holder.poll() is None:
            holder.kill()
    assert restore.returncode == 3, restore.stderr
    assert restore.stderr.strip().splitlines()[-1] == (
        "error: node 5: TTA-PRO stores parameters only with the drive disabled; disable it first — nothing was written"
    )
    assert restore.stdout == ""
    assert memory.get(730) == before
    read = httpx.get(f"{server.url}/api/buses/pb/nodes/5/objects/kp_speed", timeout=15).json()
    assert read["raw"] == before
