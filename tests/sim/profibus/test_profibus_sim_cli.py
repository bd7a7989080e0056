"""`servostudio sim --nodes 5:ttapro` with its PROFIBUS endpoints announced in the start-up JSON line."""

from __future__ import annotations

import argparse
import json
import os
import signal
import subprocess
import sys

import pytest
from tests.sim.profibus.dp_test_master import TestMaster, parse_response, sd1

from servostudio.sim.profibus.cli_options import split_nodes


def start(*options: str) -> subprocess.Popen:
    command = [sys.executable, "-m", "servostudio", "sim", *options]
    return subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def stop(process: subprocess.Popen) -> None:
    process.send_signal(signal.SIGTERM)
    assert process.wait(10) == 0


def test_the_pty_endpoint_is_announced_and_answers() -> None:
    process = start("--nodes", "5:ttapro", "--profibus-pty")
    try:
        description = json.loads(process.stdout.readline())
        assert description["nodes"] == {"5": "ttapro"}
        assert description["profibus_pty"].startswith("/dev/pts/")
        assert "socketcand" not in description  # no CANopen node, no CAN bus
        descriptor = os.open(description["profibus_pty"], os.O_RDWR | os.O_NOCTTY)
        try:
            os.write(descriptor, sd1(5, 0x49))
            assert parse_response(os.read(descriptor, 6)) == ("SD1", 0x00, b"")
        finally:
            os.close(descriptor)
    finally:
        stop(process)


def test_the_tcp_endpoint_sits_beside_the_can_nodes() -> None:
    process = start("--nodes", "1,5:ttapro", "--socketcand", "127.0.0.1:0", "--profibus-tcp", "127.0.0.1:0")
    try:
        description = json.loads(process.stdout.readline())
        assert description["nodes"] == {"1": "xtrapulspac", "5": "ttapro"}
        host, port = description["profibus_tcp"].removeprefix("socket://").split(":")
        master = TestMaster(host, int(port), slave=5)
        try:
            master.parameterise()
            assert master.read(700)[3] == 4
        finally:
            master.close()
    finally:
        stop(process)


@pytest.mark.parametrize(
    ("nodes", "pty", "message"),
    [
        ("5:ttapro", False, "give --profibus-pty or --profibus-tcp"),
        ("1", True, "need a ttapro node"),
        ("126:ttapro", True, "a DP station address is 1..125"),
    ],
)
def test_inconsistent_options_are_refused(nodes: str, pty: bool, message: str) -> None:
    options = argparse.Namespace(
        nodes=nodes, device="xtrapulspac", profibus_pty=pty, profibus_tcp=None, plant=None, seed=None
    )
    with pytest.raises(ValueError, match=message):
        split_nodes(options)


def test_a_refused_option_exits_with_the_invalid_input_code() -> None:
    process = start("--nodes", "5:ttapro")
    _, error = process.communicate(timeout=30)
    assert process.returncode == 3 and "give --profibus-pty or --profibus-tcp" in error
