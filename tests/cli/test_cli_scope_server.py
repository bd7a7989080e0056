"""``servostudio scope … --server URL``: the capture made by a real ``servostudio serve`` on its simulated drives, the
files written here exactly as the local command writes them, refusals (exit 3) before anything is armed."""

from __future__ import annotations

import csv
import json
import signal
import subprocess
import sys
import time

import httpx
from tests.support.live_server import REPO_ROOT

from servostudio.cli import main


def comment_keys(text: str) -> list[str]:
    return [line.split(":")[0] for line in text.splitlines() if line.startswith("# ")]


def test_a_capture_through_the_server_writes_the_same_files_and_summary(tmp_path, capsys, live_server):
    out, page = tmp_path / "remote.csv", tmp_path / "remote.html"
    channels = ["--ch", "0x606C,0", "--ch", "0x6078", "--ch", "statusword"]
    code = main(["--server", live_server.url, "scope", "--node", "2", *channels, "--samples", "100",
                 "--period-us", "500", "--out", str(out), "--html", str(page)])  # fmt: skip
    assert code == 0, capsys.readouterr().err
    summary = json.loads(capsys.readouterr().out)
    local_out = tmp_path / "local.csv"
    assert main(["scope", "--bus", "sim:1", "--node", "1", *channels, "--samples", "100", "--period-us", "500",
                 "--out", str(local_out)]) == 0  # fmt: skip
    local = json.loads(capsys.readouterr().out)
    assert sorted(summary) == sorted(local)
    assert {key: summary[key] for key in ("channels", "samples", "period_us", "trigger", "trigger_index")} == {
        key: local[key] for key in ("channels", "samples", "period_us", "trigger", "trigger_index")
    }
    assert summary["node"] == 2 and summary["out"] == str(out) and summary["html"] == str(page)
    text = out.read_text()
    assert comment_keys(text) == comment_keys(local_out.read_text())
    assert "# node: 2" in text and "# bus: sim" in text and "# source: recorder" in text
    rows = list(csv.reader(line for line in text.splitlines() if not line.startswith("# ")))
    assert rows[0] == ["time_s", "0x606C,0", "0x6078,0", "0x6041,0"] and len(rows) == 101
    assert [row[0] for row in rows[1:3]] == ["0", "0.0005"]
    assert "scattergl" in page.read_text()


def test_a_definition_the_drive_cannot_capture_is_refused_by_the_server_exit_3(tmp_path, capsys, live_server):
    out = tmp_path / "no.csv"
    code = main(["--server", live_server.url, "scope", "--bus", "sim", "--node", "1", "--ch", "0x606C,0",
                 "--samples", "999999", "--out", str(out)])  # fmt: skip
    assert code == 3 and "do not fit the recorder" in capsys.readouterr().err and not out.exists()


def test_no_recording_in_time_through_the_server_is_exit_5_and_no_file(tmp_path, capsys, live_server):
    out = tmp_path / "late.csv"
    code = main(["--server", live_server.url, "scope", "--node", "3", "--ch", "0x6064", "--trigger",
                 "0x6064,0:rising:1000000000", "--timeout", "0.5", "--out", str(out)])  # fmt: skip
    assert code == 5 and "no complete recording within 0.5 s" in capsys.readouterr().err and not out.exists()


def test_ctrl_c_stops_the_servers_capture_and_its_recorder(tmp_path, live_server):
    out = tmp_path / "never.csv"
    command = subprocess.Popen(
        [sys.executable, "-m", "servostudio", "--server", live_server.url, "scope", "--node", "1", "--ch", "0x6064",
         "--trigger", "0x6064,0:rising:1000000000", "--timeout", "60", "--out", str(out)],
        cwd=REPO_ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    status = f"{live_server.url}/api/buses/sim/nodes/1/scope/status"
    deadline = time.monotonic() + 30
    while httpx.get(status).json()["status"] != "waiting":
        assert time.monotonic() < deadline and command.poll() is None, command.stderr.read() if command.stderr else ""
        time.sleep(0.05)
    command.send_signal(signal.SIGINT)
    _, stderr = command.communicate(timeout=30)
    assert command.returncode == 130 and "the recorder was stopped" in stderr and not out.exists()
    after = httpx.get(status).json()
    assert after["status"] == "idle" and after["job"] is None  # the job ended and the recorder is stopped
