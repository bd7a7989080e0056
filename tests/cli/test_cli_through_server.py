"""The drive commands through a running server (issue #14 point 9): ``--server URL``, ``$SERVOSTUDIO_SERVER`` or the
config file; the same output and exit codes as on a bus of their own, and the same drives as the server's.

The server (a real ``servostudio serve``) and the headless commands reach the same simulated drives over socketcand,
so each answer through the server can be checked against the drive itself.
"""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time

import pytest
from tests.support.commands import run_json
from tests.support.live_server import LiveServer

from servostudio.cli import main
from servostudio.cli.remote import CONFIG_VARIABLE, SERVER_VARIABLE


@pytest.fixture(scope="module")
def server(socketcand, tmp_path_factory):
    projects = tmp_path_factory.mktemp("through-server") / "projects"
    projects.mkdir()
    live = LiveServer(projects, ["--bus", socketcand.spec])
    try:
        live.wait_ready()
        yield live
    finally:
        live.stop()


def test_read_and_write_through_the_server_answer_as_the_drive_itself(server, socketcand, capsys):
    code, written, _ = run_json(capsys, "write", "--server", server.url, "--node", "1", "0x60F9,2", "123")
    assert code == 0 and written["raw"] == 123
    here = run_json(capsys, "read", "--bus", socketcand.spec, "--node", "1", "0x60F9,2", "statusword")
    through = run_json(capsys, "read", "--server", server.url, "--node", "1", "0x60F9,2", "statusword")
    assert through == here and here[1][0]["raw"] == 123


def test_the_default_server_comes_from_the_environment_and_bus_stays_headless(server, socketcand, capsys, monkeypatch):
    monkeypatch.setenv(SERVER_VARIABLE, server.url)
    code, value, _ = run_json(capsys, "read", "--node", "2", "0x6041")
    assert code == 0 and value["index"] == 0x6041
    monkeypatch.setenv(SERVER_VARIABLE, "http://127.0.0.1:9")  # nobody listens there: --bus must not go there
    code, value, _ = run_json(capsys, "read", "--bus", socketcand.spec, "--node", "2", "0x6041")
    assert code == 0 and value["index"] == 0x6041
    code, _, error = run_json(capsys, "read", "--node", "2", "0x6041")
    assert code == 5 and "cannot be reached" in error


def test_the_default_server_comes_from_the_config_file(server, capsys, monkeypatch, tmp_path):
    config = tmp_path / "config.toml"
    config.write_text(f'server = "{server.url}"\n', encoding="utf-8")
    monkeypatch.setenv(CONFIG_VARIABLE, str(config))
    code, nodes, _ = run_json(capsys, "scan")
    assert code == 0 and [node["node"] for node in nodes] == [1, 2, 3]


def test_bus_names_the_servers_bus_by_name_or_by_any_spelling_of_its_spec(server, socketcand, capsys):
    for bus in ("socketcand", f"{socketcand.spec}/can0", socketcand.spec):
        code, value, _ = run_json(capsys, "read", "--server", server.url, "--bus", bus, "--node", "3", "0x6041")
        assert code == 0 and value["node"] == 3
    code, _, error = run_json(capsys, "read", "--server", server.url, "--bus", "virtual:other", "--node", "3", "0x6041")
    assert code == 4 and "has no bus 'virtual:other' open (open: socketcand)" in error


def test_exit_codes_are_the_servers_kinds(server, capsys):
    assert run_json(capsys, "read", "--server", server.url, "--node", "1", "0x2FFE")[0] == 4  # not in the dictionary
    assert run_json(capsys, "write", "--server", server.url, "--node", "1", "0x6041", "1")[0] == 3  # read-only
    assert run_json(capsys, "read", "--server", server.url, "--node", "44", "0x6041")[0] == 4  # no such node
    assert run_json(capsys, "nmt", "--server", server.url, "sing")[0] == 3  # refused before the server is asked
    code, answer, _ = run_json(capsys, "nmt", "--server", server.url, "pre-operational", "--node", "3")
    assert (code, answer) == (0, {"command": "pre-operational", "node": 3})


def test_backup_and_restore_keep_the_files_here_and_reach_the_servers_drive(server, socketcand, capsys, tmp_path):
    here, through = tmp_path / "here.DRIVEPAR.TXT", tmp_path / "through.DRIVEPAR.TXT"
    code, result, _ = run_json(capsys, "backup", "--server", server.url, "--node", "2", "--out", str(through))
    assert code == 0 and result["file"] == str(through) and result["objects"] > 300
    code, local, _ = run_json(capsys, "backup", "--bus", socketcand.spec, "--node", "2", "--out", str(here))
    assert code == 0 and _entries(through) == _entries(here)
    assert {key: result[key] for key in ("objects", "skipped", "kind")} == {
        key: local[key] for key in ("objects", "skipped", "kind")
    }
    through.write_text(_set(through, "0x60F9,2", 77), encoding="latin-1")
    code, restored, _ = run_json(
        capsys, "restore", "--server", server.url, "--node", "2", "--in", str(through), "--no-store"
    )
    assert code == 0 and restored["ok"] and restored["file"] == str(through) and restored["stored"] == ""
    assert run_json(capsys, "read", "--bus", socketcand.spec, "--node", "2", "0x60F9,2")[1]["raw"] == 77
    through.write_text("0x60F9,2=70000\n", encoding="latin-1")  # out of range: refused, nothing written
    code, _, error = run_json(capsys, "restore", "--server", server.url, "--node", "2", "--in", str(through))
    assert code == 3 and "DRIVEPAR.TXT:1" in error
    assert run_json(capsys, "read", "--bus", socketcand.spec, "--node", "2", "0x60F9,2")[1]["raw"] == 77


def test_backup_of_every_node_into_a_directory(server, capsys, tmp_path):
    code, results, _ = run_json(capsys, "backup", "--server", server.url, "--out", str(tmp_path / "all"))
    assert code == 0 and sorted(results) == ["1", "2", "3"]
    assert all((tmp_path / "all" / f"node{node}" / "DRIVEPAR.TXT").is_file() for node in (1, 2, 3))
    code, restored, _ = run_json(
        capsys, "restore", "--server", server.url, "--node", "3", "--in", str(tmp_path / "all")
    )
    assert code == 0 and all(item["ok"] for item in restored["3"])


def test_share_gives_the_servers_bus_to_canopen_and_off_ends_it(server, capsys):
    import canopen

    code, shared, _ = run_json(capsys, "share", "--server", server.url)
    assert code == 0 and shared["bus"] == "socketcand" and shared["port"] > 0
    network = canopen.Network()
    network.connect(interface="socketcand", channel="can0", host="127.0.0.1", port=shared["port"])
    try:
        assert network.add_node(1, canopen.ObjectDictionary()).sdo.upload(0x1008, 0) == b"XtrapulsPac"
    finally:
        network.disconnect()
    assert run_json(capsys, "share", "--server", server.url, "--off")[1] == {"bus": "socketcand", "shared": False}
    assert run_json(capsys, "share", "--bus", "sim")[0] == 3  # a bus of this process is not shared


def test_enabling_through_the_server_holds_until_interrupted_then_stops(server, socketcand):
    command = [sys.executable, "-m", "servostudio", "state", "--server", server.url, "--node", "2", "operation-enabled"]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        line = process.stderr.readline()
        assert "holding" in line, line + process.stderr.read()
        assert _state(socketcand.spec, 2) == "OPERATION ENABLED"
        process.send_signal(signal.SIGINT)
        out, err = process.communicate(timeout=30)
    finally:
        if process.poll() is None:
            process.kill()
    assert process.returncode == 0, err
    assert json.loads(out)["state"] in ("QUICK STOP ACTIVE", "SWITCH ON DISABLED")  # the state after the stop
    deadline = time.monotonic() + 5
    while _state(socketcand.spec, 2) == "OPERATION ENABLED" and time.monotonic() < deadline:
        time.sleep(0.1)
    assert _state(socketcand.spec, 2) in ("QUICK STOP ACTIVE", "SWITCH ON DISABLED")
    assert main(["state", "--bus", socketcand.spec, "--node", "2", "switch-on-disabled"]) == 0


def _state(spec: str, node: int) -> str:
    from servostudio.drive.control import read_state
    from servostudio.services.bus import ConnectionManager

    manager = ConnectionManager()
    try:
        state, _ = read_state(manager.open(spec).drive(node))
        return state.value if state else ""
    finally:
        manager.close_all()


def _entries(path) -> list[str]:
    return [line for line in path.read_text(encoding="latin-1").splitlines() if not line.startswith(";")]


def _set(path, key: str, value: int) -> str:
    lines = [f"{key}={value}" if line.startswith(f"{key}=") else line for line in _entries(path)]
    return "\n".join(lines) + "\n"
