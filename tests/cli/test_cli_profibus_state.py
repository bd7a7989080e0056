"""`servostudio state` on a TTA-PRO (docs/profibus.md §12): the state read from the PZD status word, and
`operation-enabled` holding the axis through PZD while the command runs, then quick-stopping it — each read back
from the simulated slave (in this process, over its TCP stream; the command in a process of its own)."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time

import pytest
from tests.support.profibus_line import ttapro_line

from servostudio.cli import main
from servostudio.sim.drive.statemachine import State


@pytest.fixture(scope="module")
def line():
    with ttapro_line(5) as line:
        yield line


def drive_state(line) -> State:
    with line.line.lock:
        return line.slaves[5].drive.device.state


def test_state_reads_the_pzd_status_word(line, capsys):
    code = main(["state", "--bus", line.spec, "--node", "5"])
    shown = json.loads(capsys.readouterr().out)
    assert code == 0 and shown["state"] == "SWITCH ON DISABLED" and shown["statusword"] & 0x0040


def test_enable_holds_through_pzd_until_interrupted_then_quick_stops(line):
    command = [sys.executable, "-m", "servostudio", "state", "--bus", line.spec, "--node", "5", "operation-enabled"]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        said = process.stderr.readline()
        assert "holding" in said, said + process.stderr.read()
        assert drive_state(line) is State.OPERATION_ENABLED
        process.send_signal(signal.SIGTERM)
        out, err = process.communicate(timeout=30)
    finally:
        if process.poll() is None:
            process.kill()
    assert process.returncode == 0, err
    assert json.loads(out)["state"] in ("QUICK STOP ACTIVE", "SWITCH ON DISABLED")
    deadline = time.monotonic() + 2
    while drive_state(line) is State.OPERATION_ENABLED and time.monotonic() < deadline:
        time.sleep(0.01)
    assert drive_state(line) is State.SWITCH_ON_DISABLED
    assert not line.slaves[5].drive.faults.faulted  # stopped by the quick stop, not by the lost master's watchdog
