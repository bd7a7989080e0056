"""The CLI from a shell script, as an automation user would call it (tests/cli/cli_roundtrip.sh)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from servostudio.services.bus import ConnectionManager
from servostudio.services.scan import scan

SCRIPT = Path(__file__).with_name("cli_roundtrip.sh")


@pytest.fixture(scope="module")
def commissioned_bus(socketcand, commission):
    manager = ConnectionManager()
    bus = manager.open(socketcand.spec)
    scan(bus, nodes=[1])
    commission(bus.drive(1))
    manager.close_all()
    return socketcand.spec


def test_cli_round_trip(commissioned_bus, tmp_path):
    executable = Path(sys.executable).with_name("servostudio")
    environment = {**os.environ, "SERVOSTUDIO": str(executable), "PATH": f"{executable.parent}:{os.environ['PATH']}"}
    result = subprocess.run(
        ["bash", str(SCRIPT), commissioned_bus, str(tmp_path)],
        capture_output=True,
        text=True,
        env=environment,
        timeout=180,
    )
    assert result.returncode == 0, f"{result.stdout}\n{result.stderr}"
    assert "cli round trip ok" in result.stdout
