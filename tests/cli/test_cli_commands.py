"""The drive commands in-process (main(argv)): JSON on stdout, exit codes, errors on stderr."""

from __future__ import annotations

import pytest
from tests.support.commands import run_json


@pytest.fixture(scope="module")
def bus(socketcand):
    return socketcand.spec


def test_scan_lists_the_drives(bus, capsys):
    code, nodes, _ = run_json(capsys, "scan", "--bus", bus)
    assert code == 0 and [node["node"] for node in nodes] == [1, 2, 3]


def test_state_and_fault_commands(bus, capsys):
    code, state, _ = run_json(capsys, "state", "--bus", bus, "--node", "3", "switched-on")
    assert code == 0 and state["state"] == "SWITCHED ON"
    code, state, _ = run_json(capsys, "state", "--bus", bus, "--node", "3", "switch-on-disabled")
    assert state["state"] == "SWITCH ON DISABLED"
    code, report, _ = run_json(capsys, "fault", "--bus", bus, "--node", "3", "--reset")
    assert code == 0 and report["fault"] is False and report["faults"] == []


def test_nmt_and_its_refusal(bus, capsys):
    code, answer, _ = run_json(capsys, "nmt", "--bus", bus, "start", "--node", "2")
    assert code == 0 and answer == {"command": "start", "node": 2}
    code, _, error = run_json(capsys, "nmt", "--bus", bus, "--node", "2", "jump")
    assert code == 3 and "unknown NMT command 'jump'" in error


def test_refused_write_and_silent_node(bus, capsys):
    code, _, error = run_json(capsys, "write", "--bus", bus, "--node", "1", "0x3410,1", "99")
    assert code == 3 and "99 is outside 1..24" in error
    code, _, error = run_json(capsys, "read", "--bus", bus, "--node", "42", "0x1000")
    assert code == 5 and "node 42 does not answer" in error


def test_unknown_object_and_unreachable_bus(bus, capsys):
    code, _, error = run_json(capsys, "read", "--bus", bus, "--node", "1", "0x2FFE")
    assert code == 4 and "0x2FFE" in error
    code, _, error = run_json(capsys, "read", "--bus", "socketcand:127.0.0.1:9", "--node", "1", "0x1000")
    assert code == 5 and "not connected" in error
    code, _, error = run_json(capsys, "read", "--bus", "usb:0", "--node", "1", "0x1000")
    assert code == 3 and "unknown interface" in error
