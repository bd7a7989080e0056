"""``servostudio scope`` as scripts use it: the pinned options, the CSV exactly as pinned, refusals (exit 3) and
failures (exit 5) that leave no file, a trigger fired while the command waits."""

from __future__ import annotations

import csv
import json
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest
from tests.support.embedded_sim import SDO_TIMEOUT

from servostudio.cli import main
from servostudio.services.bus import ConnectionManager

REPO = Path(__file__).resolve().parents[2]


def run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "servostudio", "scope", *args], capture_output=True, text=True, cwd=REPO, timeout=120
    )


@pytest.fixture
def peer(socketcand):
    """A second SDO client of the simulated drives, for before and after a command: never while it runs, since two
    clients of one node's SDO channel would answer each other's transfers."""
    manager = ConnectionManager()
    connection = manager.open(socketcand.spec, wait=5.0)
    connection.engine.timeout = SDO_TIMEOUT
    yield connection
    manager.close_all()


def wait_recorder(network, node: int, status: int, timeout: float = 30.0) -> None:
    """Until the simulated recorder shows ``status`` (read inside the simulator, so the command's SDO is alone)."""
    deadline = time.monotonic() + timeout
    while True:
        with network.lock:
            current = network.node(node).store.get(0x5829, 0)
        if current == status:
            return
        assert time.monotonic() < deadline, f"recorder of node {node} is at {current}, never reached {status}"
        time.sleep(0.01)


def set_point(network, node: int, key: tuple[int, int], value: int) -> None:
    """What an operator's set-point does inside the drive, without a second SDO client."""
    with network.lock:
        store = network.node(node).store
        store.write_value(store.od[key], value)


def test_an_immediate_capture_writes_the_pinned_csv_and_an_html_file(tmp_path, capsys):
    out, page = tmp_path / "speed.csv", tmp_path / "speed.html"
    code = main(["scope", "--bus", "sim:1", "--node", "1", "--ch", "0x606C,0", "--ch", "0x6078", "--ch", "statusword",
                 "--samples", "100", "--period-us", "500", "--out", str(out), "--html", str(page)])  # fmt: skip
    assert code == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["samples"] == 100 and summary["period_us"] == 500 and summary["trigger"] == "immediate"
    lines = out.read_text().splitlines()
    comments = [line for line in lines if line.startswith("# ")]
    assert [line.split(":")[0] for line in comments] == [
        "# period", "# samples", "# trigger", "# pre-trigger", "# units", "# drive", "# node", "# bus", "# captured",
        "# source",
    ]  # fmt: skip
    assert (
        comments[0] == "# period: 500 us"
        and comments[2] == "# trigger: immediate"
        and comments[-1] == "# source: recorder"
    )
    assert comments[4] == "# units: s,user unit/s,% rated current," and comments[6] == "# node: 1"
    assert comments[5].startswith("# drive: xtrapulspac XtrapulsPac (vendor 0x")
    rows = list(csv.reader(lines[len(comments) :]))
    assert rows[0] == ["time_s", "0x606C,0", "0x6078,0", "0x6041,0"]
    assert lines[len(comments)] == 'time_s,"0x606C,0","0x6078,0","0x6041,0"'
    assert [row[0] for row in rows[1:4]] == ["0", "0.0005", "0.001"] and len(rows) == 101
    assert "scattergl" in page.read_text()


def test_a_trigger_fired_while_the_command_waits(tmp_path, socketcand, sim_network):
    out = tmp_path / "step.csv"
    set_point(sim_network, 2, (0x60FF, 0), 0)
    command = subprocess.Popen(
        [sys.executable, "-m", "servostudio", "scope", "--bus", socketcand.spec, "--node", "2", "--ch", "0x60FF,0",
         "--ch", "0x6064,0", "--samples", "200", "--trigger", "0x60FF,0:rising:100", "--pretrigger", "20",
         "--timeout", "60", "--out", str(out)],
        cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    wait_recorder(sim_network, 2, 2)  # waiting for the trigger
    set_point(sim_network, 2, (0x60FF, 0), 500)
    stdout, stderr = command.communicate(timeout=60)
    assert command.returncode == 0, stderr
    assert json.loads(stdout)["trigger_index"] == 40
    text = out.read_text()
    assert "# trigger: 0x60FF,0 rising 100 user unit/s\n# pre-trigger: 20 % (40 samples)\n" in text
    rows = {row[0]: row for row in csv.reader(line for line in text.splitlines() if not line.startswith("#"))}
    assert rows["0"][1] == "500" and rows["-0.00025"][1] == "0"


@pytest.mark.parametrize(
    ("args", "reason"),
    [
        (["--ch", "0x6041", "--period-us", "300"], "multiple of its 250 µs base period"),
        (["--ch", "0x306C"], "cannot be recorded"),
        (["--ch", "0x6041", "--trigger", "0x6041:up:1"], "trigger edge 'up'"),
        (["--ch", "0x6041", "--trigger", "0x6041,0:rising:70000"], "can never fire rising"),
        (["--ch", "0x6041", "--pretrigger", "20"], "a pre-trigger needs a trigger"),
    ],
)
def test_refused_before_anything_is_armed_exit_3_and_no_file(tmp_path, capsys, args, reason):
    out = tmp_path / "no.csv"
    assert main(["scope", "--bus", "sim:1", "--node", "1", *args, "--out", str(out)]) == 3
    assert reason in capsys.readouterr().err and not out.exists()


def test_trigger_and_immediate_exclude_each_other_and_an_unreachable_server_is_exit_5(tmp_path):
    both = run("--bus", "sim:1", "--node", "1", "--ch", "0x6041", "--immediate", "--trigger", "0x6041:rising:1",
               "--out", str(tmp_path / "x.csv"))  # fmt: skip
    assert both.returncode == 2 and "not allowed with argument" in both.stderr
    remote = subprocess.run(
        [sys.executable, "-m", "servostudio", "--server", "http://127.0.0.1:9", "scope", "--bus", "sim:1", "--node",
         "1", "--ch", "0x6041", "--out", str(tmp_path / "x.csv")],
        capture_output=True, text=True, cwd=REPO, timeout=60,
    )  # fmt: skip
    assert remote.returncode == 5 and "cannot be reached" in remote.stderr and not (tmp_path / "x.csv").exists()


def test_no_recording_in_time_exit_5_and_no_file(tmp_path, capsys, socketcand, peer):
    out = tmp_path / "late.csv"
    code = main(["scope", "--bus", socketcand.spec, "--node", "3", "--ch", "0x6064", "--trigger",
                 "0x6064,0:rising:1000000000", "--timeout", "0.5", "--out", str(out)])  # fmt: skip
    assert code == 5 and "no complete recording within 0.5 s" in capsys.readouterr().err and not out.exists()
    assert peer.drive(3).read("0x5829").raw == 0  # stopped


def test_a_link_cut_during_the_upload_exit_5_no_file_and_the_next_capture_works(
    tmp_path, capsys, socketcand, sim_network, slow
):
    out = tmp_path / "cut.csv"
    arguments = ["scope", "--bus", socketcand.spec, "--node", "1", "--ch", "0x6064", "--ch", "0x606C", "--ch",
                 "0x6062", "--ch", "0x60F4", "--period-us", "1000", "--samples", "2048", "--out", str(out)]  # fmt: skip
    codes: list[int] = []
    command = threading.Thread(target=lambda: codes.append(main(arguments)))
    command.start()
    wait_recorder(sim_network, 1, 3)  # recording for 2 s
    with slow(sim_network):
        wait_recorder(sim_network, 1, 4)  # recorded: the upload of 32 KB at 2 ms per segment takes about 10 s
        time.sleep(0.5)
        socketcand.cut()
        command.join(60)
    socketcand.restore()
    assert codes == [5] and "the upload of the recording failed" in capsys.readouterr().err
    assert not out.exists() and not list(tmp_path.iterdir())  # not even a temporary file
    short = [*arguments[:-8], "--samples", "64", "--out", str(out)]
    assert main(short) == 0 and out.exists()


def test_plan_states_rate_and_bus_load_and_arms_nothing(tmp_path, capsys):
    code = main(["scope", "--bus", "sim:1,2:cd1k", "--node", "2", "--ch", "0x6064,0", "--ch", "0x6064,0@1",
                 "--period-us", "2000", "--plan"])  # fmt: skip
    assert code == 0, capsys.readouterr().err
    plan = json.loads(capsys.readouterr().out)
    assert plan["source"] == "tpdo" and [channel["key"] for channel in plan["channels"]] == ["0x6064,0", "0x6064,0@1"]
    stream = plan["stream"]
    assert stream["rate_hz"] == 500 and stream["nodes"] == [2, 1] and stream["frames_per_s"] == 1500
    assert stream["bus_load"] == pytest.approx((2 * 95 + 55) / 2000)  # two 4-byte TPDOs (95 bits) and the SYNC (55)
    assert "same SYNC frame" in stream["alignment"]


def test_a_cd1k_capture_through_tpdos_with_a_second_axis(tmp_path, capsys):
    out = tmp_path / "two.csv"
    code = main(["scope", "--bus", "sim:1,2:cd1k", "--node", "2", "--ch", "0x6041,0", "--ch", "0x6041,0@1",
                 "--period-us", "1000", "--samples", "50", "--out", str(out)])  # fmt: skip
    assert code == 0, capsys.readouterr().err
    summary = json.loads(capsys.readouterr().out)
    assert summary["source"] == "tpdo" and summary["channels"] == ["0x6041,0", "0x6041,0@1"]
    text = out.read_text()
    assert "# source: tpdo" in text and 'time_s,"0x6041,0","0x6041,0@1"' in text
    rows = list(csv.reader(line for line in text.splitlines() if not line.startswith("# ")))
    assert len(rows) == 51 and [row[0] for row in rows[1:3]] == ["0", "0.001"]


def test_a_two_axis_recorder_capture_summary_says_how_it_was_armed(tmp_path, capsys):
    out = tmp_path / "axes.csv"
    code = main(["scope", "--bus", "sim:1,2", "--node", "1", "--ch", "0x6064,0", "--ch", "0x6064,0@2", "--source",
                 "recorder", "--samples", "50", "--out", str(out)])  # fmt: skip
    assert code == 0, capsys.readouterr().err
    summary = json.loads(capsys.readouterr().out)
    assert summary["arm"] == "broadcast" and "one broadcast frame armed every recorder" in summary["arm_note"]
    assert summary["alignment_ns"] == 250_000 and summary["channels"] == ["0x6064,0", "0x6064,0@2"]
    single = main(["scope", "--bus", "sim:1", "--node", "1", "--ch", "0x6064,0", "--samples", "20", "--out", str(out)])
    assert single == 0 and json.loads(capsys.readouterr().out)["arm"] is None  # one drive: nothing to say
