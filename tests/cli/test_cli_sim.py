"""`servostudio sim` as a separate process: endpoints announced as JSON, reachable, clean stop on SIGTERM."""

from __future__ import annotations

import argparse
import json
import signal
import socket
import subprocess
import sys

import can
import pytest

from servostudio.cli.sim import host_port
from servostudio.transport.rs232_framing import DRIVE_HEADER, HOST_HEADER, FrameDecoder, encode_frame


def test_host_port_parsing():
    assert host_port("127.0.0.1:29536") == ("127.0.0.1", 29536)
    assert host_port("localhost:0") == ("localhost", 0)
    for bad in ("29536", ":80", "host:", "host:http", "host:70000"):
        with pytest.raises(argparse.ArgumentTypeError):
            host_port(bad)


def test_sim_command_serves_socketcand_and_the_serial_link(tmp_path):
    process = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "servostudio",
            "sim",
            "--nodes",
            "1,2",
            "--socketcand",
            "127.0.0.1:0",
            "--serial-tcp",
            "127.0.0.1:0",
            "--bitrate",
            "500000",
            "--state-dir",
            str(tmp_path),
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        description = json.loads(process.stdout.readline())
        assert description["nodes"] == {"1": "xtrapulspac", "2": "xtrapulspac"}
        endpoint = description["socketcand"]
        with can.Bus(interface="socketcand", host=endpoint["host"], port=endpoint["port"], channel="can0") as bus:
            bus.send(can.Message(arbitration_id=0x602, data=[0x40, 0x18, 0x10, 1, 0, 0, 0, 0], is_extended_id=False))
            response = None
            while response is None or response.arbitration_id != 0x582:
                response = bus.recv(10)
                assert response is not None
            assert bytes(response.data[:4]) == bytes([0x43, 0x18, 0x10, 0x01])
        host, port = description["serial_tcp"].removeprefix("socket://").split(":")
        with socket.create_connection((host, int(port)), timeout=10) as line:
            line.sendall(encode_frame(HOST_HEADER, 0x642, bytes([0x40, 0x18, 0x10, 1])))
            decoder, frames = FrameDecoder(DRIVE_HEADER), []
            while not frames:
                frames = decoder.feed(line.recv(64))
        assert frames[0][0] == 0x5C2 and frames[0][1][:4] == bytes([0x43, 0x18, 0x10, 0x01])
    finally:
        process.send_signal(signal.SIGTERM)
        assert process.wait(timeout=20) == 0, process.stderr.read()


def test_bad_node_list_is_a_clear_error():
    result = subprocess.run(
        [sys.executable, "-m", "servostudio", "sim", "--nodes", "1,1", "--socketcand", "127.0.0.1:0"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert result.returncode == 3
    assert "node ID 1 appears twice" in result.stderr
