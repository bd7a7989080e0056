"""``servostudio scope … --roll --seconds S --out FILE.csv`` (pinned, docs/scope.md §8): every sample of the roll in
the capture CSV, in sequence; a cut link is a gap stated in the comments, its sequence numbers without rows; the
same file through a running server (REST + the roll's WebSocket); an over-subscribed roll is exit 3 and no file."""

from __future__ import annotations

import csv
import json
import signal
import subprocess
import sys
import threading
import time
from decimal import Decimal
from pathlib import Path

import pytest

from servostudio.cli import main
from servostudio.services.scope.rollfile import RollRecord

REPO = Path(__file__).resolve().parents[2]
FOUR = ["--ch", "0x6064,0", "--ch", "0x606C,0", "--ch", "statusword", "--ch", "0x6078"]
HEADER = ["time_s", "0x6064,0", "0x606C,0", "0x6041,0", "0x6078,0"]
CAPTURE_KEYS = ["period", "samples", "trigger", "pre-trigger", "units", "drive", "node", "bus", "captured", "source"]


def read_roll(text: str) -> tuple[dict[str, list[str]], list[list[str]]]:
    """The comments (key → values, in order) and the CSV rows (header first)."""
    comments: dict[str, list[str]] = {}
    lines = text.splitlines()
    for line in lines:
        if line.startswith("# "):
            key, _, value = line[2:].partition(": ")
            comments.setdefault(key, []).append(value)
    return comments, list(csv.reader(line for line in lines if not line.startswith("# ")))


def sequence_numbers(rows: list[list[str]], period_s: str = "0.001") -> list[int]:
    return [int(Decimal(row[0]) / Decimal(period_s)) for row in rows[1:]]


def test_a_roll_writes_every_sample_as_the_capture_csv(tmp_path, capsys):
    out = tmp_path / "roll.csv"
    assert main(["scope", "--bus", "sim:1", "--node", "1", *FOUR, "--roll", "--seconds", "2", "--out", str(out)]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["samples"] == 2000 and summary["gaps"] == [] and summary["lost"] == 0
    comments, rows = read_roll(out.read_text())
    assert list(comments) == [*CAPTURE_KEYS, "gaps"]  # the capture CSV's comments, in order, then the gaps
    assert comments["period"] == ["1000 us"] and comments["samples"] == ["2000"] and comments["source"] == ["tpdo"]
    assert comments["trigger"] == ["immediate"] and comments["gaps"] == ["0"] and comments["node"] == ["1"]
    assert comments["units"] == ["s,user unit,user unit/s,,% rated current"]
    assert rows[0] == HEADER and sequence_numbers(rows) == list(range(2000))  # time 0 = the first sample


def test_a_cut_link_is_a_gap_stated_in_the_comments(tmp_path, capsys, socketcand, monkeypatch):
    take, cut_at = RollRecord.take, []

    def cut_once(record: RollRecord, event: dict) -> None:
        take(record, event)
        if event["type"] == "samples" and event["seq"] > 500 and not cut_at:
            cut_at.append(event["seq"])
            socketcand.cut()
            threading.Timer(0.5, socketcand.restore).start()

    monkeypatch.setattr(RollRecord, "take", cut_once)
    out = tmp_path / "cut.csv"
    code = main(["scope", "--bus", socketcand.spec, "--node", "1", *FOUR, "--roll", "--seconds", "4",
                 "--out", str(out)])  # fmt: skip
    assert code == 0, capsys.readouterr().err
    summary = json.loads(capsys.readouterr().out)
    gaps = [(gap["from"], gap["to"], gap["reason"]) for gap in summary["gaps"]]
    assert gaps and any(end - start >= 300 for start, end, _ in gaps)  # the cut lasted 0.5 s at 1 kHz
    comments, rows = read_roll(out.read_text())  # a loaded host may lose more: every gap is stated, each once
    assert comments["gaps"] == [f"{len(gaps)} ({sum(end - start for start, end, _ in gaps)} samples lost)"]
    stated = [f"samples {start}..{end - 1}" for start, end, _ in gaps]
    assert [line.split(" (")[0] for line in comments["gap"]] == stated
    assert all(line.endswith(f"lost: {reason}") for line, (_, _, reason) in zip(comments["gap"], gaps, strict=True))
    lost = {n for start, end, _ in gaps for n in range(start, end)}
    assert sequence_numbers(rows) == [n for n in range(4000) if n not in lost]  # no row for a lost number, no other


@pytest.mark.parametrize(
    ("args", "reason"),
    [
        ([*FOUR, "--ch", "0x6062"], "up to 4 channels per axis"),
        ([*FOUR, "--period-us", "500"], "1000 µs at the fastest"),
    ],
)
def test_an_over_subscribed_roll_is_exit_3_and_no_file(tmp_path, capsys, args, reason):
    out = tmp_path / "no.csv"
    assert main(["scope", "--bus", "sim:1", "--node", "1", *args, "--roll", "--seconds", "1", "--out", str(out)]) == 3
    assert reason in capsys.readouterr().err and not out.exists()


def test_roll_options_are_checked_before_the_bus_is_opened(tmp_path, capsys):
    with pytest.raises(SystemExit) as no_seconds:
        main(["scope", "--bus", "sim:1", "--node", "1", "--ch", "0x6064", "--roll", "--out", str(tmp_path / "x.csv")])
    assert no_seconds.value.code == 2 and "--roll needs --seconds" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["scope", "--bus", "sim:1", "--node", "1", "--ch", "0x6064", "--roll", "--seconds", "1",
              "--trigger", "0x6064:rising:1", "--out", str(tmp_path / "x.csv")])  # fmt: skip
    assert "--roll does not take --trigger" in capsys.readouterr().err


def test_a_roll_through_the_server_writes_the_same_file(tmp_path, capsys, live_server):
    out = tmp_path / "remote.csv"
    code = main(["--server", live_server.url, "scope", "--node", "2", *FOUR, "--roll", "--seconds", "1.5",
                 "--out", str(out)])  # fmt: skip
    assert code == 0, capsys.readouterr().err
    summary = json.loads(capsys.readouterr().out)
    assert summary["samples"] == 1500 and summary["lost"] == 0 and summary["node"] == 2
    comments, rows = read_roll(out.read_text())
    assert list(comments) == [*CAPTURE_KEYS, "gaps"] and comments["node"] == ["2"] and comments["bus"] == ["sim"]
    assert comments["drive"][0].startswith("xtrapulspac XtrapulsPac (vendor 0x")
    assert rows[0] == HEADER and sequence_numbers(rows) == list(range(1500))
    refused = main(["--server", live_server.url, "scope", "--node", "2", *FOUR, "--period-us", "500", "--roll",
                    "--seconds", "1", "--out", str(tmp_path / "no.csv")])  # fmt: skip
    assert refused == 3 and "1000 µs at the fastest" in capsys.readouterr().err
    assert not (tmp_path / "no.csv").exists()


def test_ctrl_c_ends_the_roll_early_writes_what_was_rolled_and_exits_130(tmp_path, socketcand, sim_network):
    out = tmp_path / "early.csv"
    command = subprocess.Popen(
        [sys.executable, "-m", "servostudio", "scope", "--bus", socketcand.spec, "--node", "1", *FOUR, "--roll",
         "--seconds", "60", "--out", str(out)],
        cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    deadline = time.monotonic() + 60
    while sim_network.node(1).state.name != "OPERATIONAL":  # the roll started the node: its SYNCs follow
        assert time.monotonic() < deadline and command.poll() is None, command.stderr and command.stderr.read()
        time.sleep(0.02)
    time.sleep(1.0)
    command.send_signal(signal.SIGINT)
    stdout, stderr = command.communicate(timeout=60)
    assert command.returncode == 130, stderr
    comments, rows = read_roll(out.read_text())
    samples = json.loads(stdout)["samples"]
    assert 0 < samples < 60_000 and comments["samples"] == [str(samples)] and len(rows) == samples + 1
    assert sequence_numbers(rows) == list(range(samples))
