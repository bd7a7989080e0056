"""`servostudio project scan|commission|compare --drive` against a `servostudio sim` child process over socketcand."""

from __future__ import annotations

import json
import signal
import subprocess
import sys

import pytest

from servostudio.cli import main


@pytest.fixture(scope="module")
def socketcand_spec(tmp_path_factory):
    process = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "servostudio",
            "sim",
            "--nodes",
            "1",
            "--socketcand",
            "127.0.0.1:0",
            "--state-dir",
            str(tmp_path_factory.mktemp("sim-flash")),
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        endpoint = json.loads(process.stdout.readline())["socketcand"]
        yield f"socketcand:{endpoint['host']}:{endpoint['port']}"
    finally:
        process.send_signal(signal.SIGTERM)
        assert process.wait(timeout=20) == 0, process.stderr.read()


def project(store, *argv: str, capsys) -> tuple[int, dict]:
    code = main(["project", "--projects", str(store), *argv])
    output = capsys.readouterr().out
    return code, json.loads(output) if output.strip() else {}


def test_scan_commission_and_compare_from_the_command_line(tmp_path, socketcand_spec, capsys):
    store = tmp_path / "store"
    code, scanned = project(
        store, "scan", "p", "--bus", socketcand_spec, "--bus-name", "line", "--create", capsys=capsys
    )
    assert code == 0 and [(node["node_id"], node["status"], node["axis"]) for node in scanned["nodes"]] == [
        (1, "added", "Axis1")
    ]
    assert scanned["project"]["buses"] == [{"name": "line", "interface": socketcand_spec, "bitrate": None}]

    commission = subprocess.run(
        [sys.executable, "-m", "servostudio", "project", "--projects", str(store), "commission", "p", "--download"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert commission.returncode == 0, commission.stderr
    report = json.loads(commission.stdout)
    assert report["ok"] and report["axes"][0]["status"] == "ok"
    assert report["axes"][0]["files"][0]["counts"]["verified"] > 200

    assert project(store, "set", "p", "Axis1", "0x6083=131072", capsys=capsys)[0] == 0
    code, compared = project(
        store,
        "compare",
        "p",
        "Axis1",
        "--drive",
        "--only-differences",
        "--group",
        "Profile Position Mode",
        capsys=capsys,
    )
    assert code == 0 and compared["columns"] == ["drive", "project", "default"]
    assert [(row["index"], row["values"]) for row in compared["rows"]] == [
        (0x6083, {"drive": 65536, "project": 131072, "default": 65536})
    ]
    code, written = project(store, "write", "p", "Axis1", capsys=capsys)
    assert code == 0 and [(item["address"], item["status"], item["drive"]) for item in written["objects"]] == [
        ("0x6083,0", "written", 131072)
    ]


def test_a_wrong_device_exits_3_with_the_report(tmp_path, socketcand_spec, capsys):
    store = tmp_path / "store"
    # the project's bus names an in-process simulation without node 1; --via reaches the sim process instead
    assert project(store, "create", "q", "--bus", "line=sim:5", capsys=capsys)[0] == 0
    assert (
        project(store, "axis-add", "q", "K", "--device", "cd1k", "--node", "1", "--bus", "line", capsys=capsys)[0] == 0
    )
    code = main(["project", "--projects", str(store), "commission", "q", "--via", f"line={socketcand_spec}"])
    captured = capsys.readouterr()
    assert code == 3 and "axes K not commissioned" in captured.err
    axis = json.loads(captured.out)["axes"][0]
    assert (axis["status"], axis["spec"], axis["identity"]["device"]) == (
        "wrong_device",
        socketcand_spec,
        "xtrapulspac",
    )
