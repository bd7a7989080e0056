"""`servostudio state … operation-enabled` is a live client: the axis stays enabled while it runs, then stops."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time

from servostudio.drive.control import read_state
from servostudio.services.bus import ConnectionManager


def _state(spec: str, node: int) -> str:
    manager = ConnectionManager()
    try:
        state, _ = read_state(manager.open(spec).drive(node))
        return state.value
    finally:
        manager.close_all()


def test_enable_holds_until_interrupted_then_quick_stops(socketcand):
    command = [
        sys.executable,
        "-m",
        "servostudio",
        "state",
        "--bus",
        socketcand.spec,
        "--node",
        "2",
        "operation-enabled",
    ]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        line = process.stderr.readline()
        assert "holding" in line, line
        assert _state(socketcand.spec, 2) == "OPERATION ENABLED"
        process.send_signal(signal.SIGTERM)
        out, err = process.communicate(timeout=30)
    finally:
        if process.poll() is None:
            process.kill()
    assert process.returncode == 0, err
    assert json.loads(out)["state"] in ("QUICK STOP ACTIVE", "SWITCH ON DISABLED")
    deadline = time.monotonic() + 5
    while _state(socketcand.spec, 2) == "OPERATION ENABLED" and time.monotonic() < deadline:
        time.sleep(0.1)
    assert _state(socketcand.spec, 2) in ("QUICK STOP ACTIVE", "SWITCH ON DISABLED")
    subprocess.run(
        [sys.executable, "-m", "servostudio", "state", "--bus", socketcand.spec, "--node", "2", "switch-on-disabled"],
        check=True,
        capture_output=True,
        timeout=30,
    )
