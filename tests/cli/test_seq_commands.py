"""``servostudio seq …`` as pinned by issue 15, against simulated drives over socketcand: check/show/graph of files,
download and upload, and ``run`` printing one JSON line per executed sequence in the manual's order."""

from __future__ import annotations

import json

import pytest
from tests.support.sequence_programs import CONDITIONAL_JUMP, COUNTER_LOOP

from servostudio.cli import main
from servostudio.drive.cia402 import State
from servostudio.drive.control import read_state
from servostudio.services.bus import ConnectionManager

NODE = "3"
BAD = "SeqNb=1\nSeqType=SPEED\nSpeed=10\nAccelTime=200000\n"


@pytest.fixture(autouse=True)
def data_dir(tmp_path, monkeypatch):
    monkeypatch.setenv("SERVOSTUDIO_DATA_DIR", str(tmp_path / "data"))


def lines(capsys) -> list[dict]:
    return [json.loads(line) for line in capsys.readouterr().out.splitlines() if line.strip()]


def answer(capsys) -> dict:
    return json.loads(capsys.readouterr().out)


def write(tmp_path, name: str, text: str):
    path = tmp_path / name
    path.write_text(text, encoding="latin-1")
    return path


def test_check_refuses_with_file_line_keyword_and_range(tmp_path, capsys):
    path = write(tmp_path, "SEQUENCE.TXT", BAD)
    assert main(["seq", "check", str(path)]) == 3
    error = capsys.readouterr().err
    assert f"{path}:4: AccelTime: value 200000 is out of range: allowed 1..65535" in error


def test_check_show_and_graph_of_a_good_file(tmp_path, capsys):
    path = write(tmp_path, "SEQUENCE.TXT", COUNTER_LOOP)
    assert main(["seq", "check", str(path)]) == 0
    assert answer(capsys) == {"file": str(path), "ok": True, "sequences": [1, 2, 3]}
    assert main(["seq", "show", str(path)]) == 0
    shown = answer(capsys)["sequences"]
    assert [(s["sequence"], s["type"], s["values"]["SeqCount"]) for s in shown] == [
        (1, "POS", 0),
        (2, "POS", 2),
        (3, "POS", 0),
    ]
    assert main(["seq", "graph", str(path)]) == 0
    graph = answer(capsys)
    assert {(e["from"], e["to"], e["kind"]) for e in graph["edges"]} == {
        (1, 2, "next"),
        (2, 3, "next"),
        (2, 1, "counter"),
    }
    assert graph["findings"] == []


def test_a_bad_download_writes_nothing(socketcand, tmp_path, capsys):
    good = write(tmp_path, "good.TXT", COUNTER_LOOP)
    assert main(["seq", "download", "--bus", socketcand.spec, "--node", NODE, str(good)]) == 0
    capsys.readouterr()
    bad = write(tmp_path, "SEQUENCE.TXT", BAD)
    assert main(["seq", "download", "--bus", socketcand.spec, "--node", NODE, str(bad), "--store"]) == 3
    assert "SEQUENCE.TXT:4: AccelTime" in capsys.readouterr().err
    out = tmp_path / "back.TXT"
    assert main(["seq", "upload", "--bus", socketcand.spec, "--node", NODE, "--out", str(out)]) == 0
    assert answer(capsys)["sequences"] == [1, 2, 3]


@pytest.mark.parametrize(
    ("program", "bits", "order"),
    [
        (COUNTER_LOOP, None, [1, 2, 1, 2, 3]),
        (CONDITIONAL_JUMP, "1.......", [1, 2, 3]),
        (CONDITIONAL_JUMP, "0.......", [1, 4]),
    ],
)
def test_run_prints_each_executed_sequence_then_quick_stops(socketcand, tmp_path, capsys, program, bits, order):
    path = write(tmp_path, "SEQUENCE.TXT", program)
    assert main(["seq", "download", "--bus", socketcand.spec, "--node", NODE, str(path)]) == 0
    capsys.readouterr()
    extra = ["--input-bits", bits] if bits else []
    assert main(["seq", "run", "--bus", socketcand.spec, "--node", NODE, "1", "--watch", "20", *extra]) == 0
    printed = lines(capsys)
    assert [line["sequence"] for line in printed] == order
    assert all(set(line) == {"t", "sequence", "phase"} and line["phase"] == "END" for line in printed)
    assert [line["t"] for line in printed] == sorted(line["t"] for line in printed)
    manager = ConnectionManager()
    try:
        assert read_state(manager.open(socketcand.spec).drive(int(NODE)))[0] is not State.OPERATION_ENABLED
    finally:
        manager.close_all()
