"""The pinned ``servostudio bode`` command: in-process on ``--bus sim`` (the command opens its own simulated drives and
is the axis's live controller) and through ``--server`` (a live client of the server, which measures as a job).
The CSV has the pinned columns; refusals exit 3 with nothing written; a limit exceeded exits 5 with the reason.
The accuracy is judged in tests/services/frequency."""

from __future__ import annotations

import csv
import json
import os
import subprocess
import sys

import httpx
import pytest
from tests.support.commands import run
from tests.support.motion_timing import InProcessServer

QUICK = ("--periods", "2", "--base-speed", "10", "--window", "20")


@pytest.fixture(autouse=True)
def data_dir(tmp_path, monkeypatch):
    monkeypatch.setenv("SERVOSTUDIO_DATA_DIR", str(tmp_path / "data"))


def rows(path) -> list[dict[str, str]]:
    lines = [line for line in path.read_text(encoding="utf-8").splitlines() if not line.startswith("#")]
    return list(csv.DictReader(lines))


def test_bode_writes_the_pinned_csv(capsys, tmp_path):
    out = tmp_path / "plant.csv"
    code, printed, err = run(
        capsys,
        "bode",
        "--bus",
        "sim",
        "--node",
        "1",
        "--loop",
        "plant",
        "--from",
        "5",
        "--to",
        "400",
        "--points",
        "60",
        "--amplitude",
        "50",
        *QUICK,
        "--yes",
        "--out",
        str(out),
    )
    assert code == 0, err
    summary = json.loads(printed)
    assert summary["loop"] == "plant" and summary["aborted"] is None and summary["out"] == str(out)
    table = rows(out)
    assert list(table[0]) == ["freq_hz", "magnitude_db", "phase_deg", "coherence"]
    assert len(table) == summary["points"] == summary["excitation"]["points"]
    assert float(table[0]["freq_hz"]) == pytest.approx(5.0, rel=0.01)
    assert "# magnitude: dB of (velocity in rad/s) / (torque in N*m)" in out.read_text(encoding="utf-8")


def test_bode_on_a_drive_without_a_recorder_measures_through_tpdos(capsys, tmp_path):
    """The CD1-k: the same command and CSV; the response came in synchronous TPDOs, the plant per ampere (the drive
    gives no torque constant)."""
    out = tmp_path / "cd1k.csv"
    code, printed, err = run(capsys, "bode", "--bus", "sim:1:cd1k", "--node", "1", "--loop", "plant", "--to", "200",
                             *QUICK, "--yes", "--out", str(out))  # fmt: skip
    assert code == 0, err
    summary = json.loads(printed)
    assert summary["aborted"] is None and summary["excitation"]["source"] == "tpdo"
    assert list(rows(out)[0]) == ["freq_hz", "magnitude_db", "phase_deg", "coherence"]
    assert "# magnitude: dB of (velocity in rad/s) / (current in A)" in out.read_text(encoding="utf-8")


def test_without_yes_nothing_turns_and_a_bad_request_is_refused(capsys, tmp_path):
    out = tmp_path / "x.csv"
    code, printed, err = run(capsys, "bode", "--bus", "sim", "--node", "1", "--loop", "plant", "--out", str(out))
    assert code == 3 and printed == "" and "confirm with --yes" in err and not out.exists()
    code, printed, err = run(
        capsys, "bode", "--bus", "sim", "--node", "1", "--loop", "closed", "--to", "900", "--yes", "--out", str(out)
    )
    assert code == 3 and "Hz" in err and not out.exists()


def test_a_limit_exceeded_exits_5_with_the_reason(capsys, tmp_path):
    out = tmp_path / "x.csv"
    code, printed, err = run(
        capsys,
        "bode",
        "--bus",
        "sim",
        "--node",
        "1",
        "--loop",
        "closed",
        "--periods",
        "2",
        "--window",
        "0.2",
        "--yes",
        "--out",
        str(out),
    )
    assert code == 5 and "position window" in err
    assert json.loads(printed)["points"] == 0 and rows(out) == []


def servostudio(*args: str, timeout: float = 120) -> subprocess.CompletedProcess:
    command = [sys.executable, "-m", "servostudio", *args]
    return subprocess.run(command, capture_output=True, text=True, timeout=timeout, env=dict(os.environ))


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    running = InProcessServer(tmp_path_factory.mktemp("bode-cli"))
    yield running
    running.close()


def test_bode_through_the_server(server, tmp_path):
    out = tmp_path / "closed.csv"
    done = servostudio(
        "--server",
        server.url,
        "bode",
        "--bus",
        "sim",
        "--node",
        "2",
        "--loop",
        "closed",
        *QUICK,
        "--yes",
        "--out",
        str(out),
    )
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout)["loop"] == "closed"
    assert list(rows(out)[0]) == ["freq_hz", "magnitude_db", "phase_deg", "coherence"]
    assert httpx.get(f"{server.url}/api/control").json() == []  # released again
