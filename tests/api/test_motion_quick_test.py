"""The quick test's motions over REST and the event socket, each read back from the simulated drive: refused 409
without the armed live controller (REST and the terminal socket), PP moves relative and absolute reaching their
target (0x6064), homing ending homed, jogs, limits refused before the bus, and the hold-to-run keepalive."""

from __future__ import annotations

import threading
import time

import pytest
from tests.support.access import admin_app, api_client
from tests.support.jobs_api import armed

from servostudio.api.app import Settings

NODE = "/api/buses/sim/nodes/2"
MOTION = f"{NODE}/motion"


@pytest.fixture(scope="module")
def app(tmp_path_factory):
    root = tmp_path_factory.mktemp("motion")
    return admin_app(Settings(projects_dir=root / "projects", static_dir=root / "no-ui", buses=("sim",)), root / "data")


@pytest.fixture
def client(app):
    with api_client(app) as client:
        yield client
        client.post(f"{MOTION}/stop")
        client.put(f"{NODE}/state", json={"target": "switch-on-disabled"})


def read(client, key: str) -> int:
    return int(client.get(f"{NODE}/objects/{key}").json()["raw"])


def wait_end(client, timeout: float = 20.0) -> dict:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        motion = client.get(MOTION).json()
        if motion["state"] != "running":
            return motion
        time.sleep(0.05)
    raise AssertionError(f"the motion still runs after {timeout} s: {motion}")


@pytest.mark.parametrize(
    ("route", "body"),
    [
        ("jog", {"velocity": 60, "seconds": 1}),
        ("move", {"distance": 1000}),
        ("move", {"distance": 1000, "absolute": True}),
        ("home", {"method": 35}),
    ],
)
def test_motion_without_an_armed_live_controller_is_refused_and_nothing_moves(client, route, body):
    before = read(client, "0x6060")
    refused = client.post(f"{MOTION}/{route}", json=body)  # no live client at all
    assert refused.status_code == 409 and "live client" in refused.json()["detail"]
    with client.websocket_connect("/api/ws/events") as socket:  # live, but not armed
        header = {"X-Servo-Client": socket.receive_json()["client"]}
        unarmed = client.post(f"{MOTION}/{route}", json=body, headers=header)
        assert unarmed.status_code == 409 and "arm" in unarmed.json()["detail"]
    assert client.get(f"{NODE}/state").json()["state"] == "SWITCH ON DISABLED"
    assert read(client, "0x6060") == before


def test_the_terminal_socket_cannot_start_the_jog_either(client):
    assert client.put(f"{NODE}/state", json={"target": "switched-on"}).status_code == 200  # prepares: anyone
    with client.websocket_connect("/api/ws/terminal") as terminal:
        terminal.send_json({"op": "write", "bus": "sim", "node": 2, "object": "0x60FF", "value": 100})
        terminal.send_json({"op": "write", "bus": "sim", "node": 2, "object": "0x6040", "value": 15})
        assert terminal.receive_json()["type"] == "written"  # the target of a disabled axis only prepares
        assert terminal.receive_json()["kind"] == "refused_for_safety"
    assert client.get(f"{NODE}/state").json()["state"] == "SWITCHED ON"


def test_relative_then_absolute_moves_reach_their_targets(client):
    with armed(client, NODE, "motion") as (_, header):
        start = read(client, "0x6064")
        relative = client.post(f"{MOTION}/move", json={"distance": 2048, "velocity": 120}, headers=header)
        assert relative.status_code == 200, relative.text
        assert relative.json()["state"] == "running" and relative.json()["kind"] == "move"
        done = wait_end(client)
        assert done["state"] == "done", done
        assert abs(read(client, "0x6064") - (start + 2048)) <= 4
        absolute = client.post(f"{MOTION}/move", json={"distance": start - 1000, "absolute": True}, headers=header)
        assert absolute.status_code == 200, absolute.text
        assert wait_end(client)["state"] == "done"
        assert abs(read(client, "0x6064") - (start - 1000)) <= 4


def test_homing_on_the_current_position_ends_homed(client):
    with armed(client, NODE, "motion") as (socket, header):
        started = client.post(f"{MOTION}/home", json={"method": 35}, headers=header)
        assert started.status_code == 200, started.text
        ended = wait_end(client)
        assert ended["state"] == "done", ended
        statusword = read(client, "0x6041")
        assert statusword & (1 << 12) and statusword & (1 << 10)  # homing attained, target reached
        assert read(client, "0x6061") == 6
        events = [socket.receive_json() for _ in range(2)]
        assert [event["state"] for event in events] == ["running", "done"]


def test_homing_with_an_index_pulse_search_ends_homed(client):
    with armed(client, NODE, "motion") as (_, header):
        started = client.post(f"{MOTION}/home", json={"method": 34, "velocity": 30}, headers=header)
        assert started.status_code == 200, started.text
        ended = wait_end(client, timeout=30)
        assert ended["state"] == "done", ended
        assert read(client, "0x6041") & (1 << 12)


def test_an_unknown_homing_method_is_refused_before_the_bus(client):
    with armed(client, NODE, "motion") as (_, header):
        refused = client.post(f"{MOTION}/home", json={"method": 16}, headers=header)
        assert refused.status_code == 422 and "no homing method 16" in refused.json()["detail"]
    assert read(client, "0x6098") != 16


def test_the_homing_methods_carry_the_manuals_descriptions(client):
    methods = {item["method"]: item["description"] for item in client.get("/api/homing-methods/xtrapulspac").json()}
    assert set(methods) == set(range(1, 15)) | set(range(17, 31)) | {33, 34, 35, -1, -2, -3, -4}
    assert "current position" in methods[35] and "Mechanical limit" in methods[-3]
    assert client.get("/api/homing-methods/nosuchdrive").status_code == 404


def test_a_timed_jog_runs_then_stands_still(client):
    with armed(client, NODE, "motion") as (_, header):
        started = client.post(f"{MOTION}/jog", json={"velocity": 120, "seconds": 0.5}, headers=header)
        assert started.status_code == 200, started.text
        time.sleep(0.3)
        assert read(client, "0x606C") > 0  # turning forward
        assert wait_end(client)["state"] == "done"
        assert read(client, "0x60FF") == 0


@pytest.mark.parametrize(
    ("route", "body", "limit"),
    [
        ("jog", {"velocity": 301, "seconds": 1}, "velocity_rpm"),
        ("jog", {"velocity": 60, "seconds": 11}, "seconds"),
        ("move", {"distance": 4097}, "distance_revolutions"),
        ("move", {"distance": 100, "velocity": 400}, "velocity_rpm"),
        ("home", {"method": 34, "velocity": 1000}, "velocity_rpm"),
    ],
)
def test_above_the_default_limits_is_refused_before_the_bus(client, route, body, limit):
    with armed(client, NODE, "motion") as (_, header):
        target_velocity, target_position = read(client, "0x60FF"), read(client, "0x607A")
        refused = client.post(f"{MOTION}/{route}", json=body, headers=header)
        assert refused.status_code == 422 and limit in refused.json()["detail"], refused.text
        assert (read(client, "0x60FF"), read(client, "0x607A")) == (target_velocity, target_position)
        assert client.get(f"{NODE}/state").json()["state"] == "SWITCH ON DISABLED"


def test_the_user_can_raise_a_limit_and_then_move_further(client):
    assert client.get(f"{MOTION}/limits").json()["distance_revolutions"] == 1.0
    raised = client.put(f"{MOTION}/limits", json={"distance_revolutions": 2.5})
    assert raised.json()["distance_revolutions"] == 2.5 and raised.json()["velocity_rpm"] == 300.0
    assert client.put(f"{MOTION}/limits", json={"velocity_rpm": -1}).status_code == 422
    try:
        with armed(client, NODE, "motion") as (_, header):
            start = read(client, "0x6064")
            moved = client.post(f"{MOTION}/move", json={"distance": 8192, "velocity": 240}, headers=header)
            assert moved.status_code == 200, moved.text
            assert wait_end(client)["state"] == "done"
            assert abs(read(client, "0x6064") - (start + 8192)) <= 4
    finally:
        client.put(f"{MOTION}/limits", json={"distance_revolutions": 1.0})


def test_a_held_jog_runs_while_keepalives_arrive_and_stops_when_they_stop(client):
    with armed(client, NODE, "motion") as (socket, header):
        started = client.post(f"{MOTION}/jog", json={"velocity": 60, "hold": True}, headers=header)
        assert started.status_code == 200, started.text
        for _ in range(25):  # half a second of keepalives, more often than the UI's: a loaded host delays some
            socket.send_json({"type": "keepalive", "bus": "sim", "node": 2})
            time.sleep(0.02)
        running = client.get(MOTION).json()
        assert running["state"] == "running" and running["last_keepalive"] is not None
        ended = wait_end(client, timeout=2)
        assert ended["state"] == "stopped" and "no keepalive" in ended["reason"]
        assert client.get(f"{NODE}/state").json()["state"] in ("QUICK STOP ACTIVE", "SWITCH ON DISABLED")


def hold_watchdogs() -> set[threading.Thread]:
    return {thread for thread in threading.enumerate() if thread.name == "motion-hold-watch"}


def test_the_servers_shutdown_ends_its_hold_watchdog(tmp_path):
    """Every app a process starts and shuts down (each test's) must not leave its watchdog thread behind."""
    before = hold_watchdogs()
    app = admin_app(Settings(projects_dir=tmp_path / "p", static_dir=tmp_path / "no-ui", buses=("sim",)), tmp_path)
    with api_client(app) as client, armed(client, NODE, "motion") as (socket, header):
        assert client.post(f"{MOTION}/jog", json={"velocity": 30, "hold": True}, headers=header).status_code == 200
        socket.send_json({"type": "keepalive", "bus": "sim", "node": 2})
        started = hold_watchdogs() - before
        assert len(started) == 1  # the app's watchdog runs while it holds a motion
        assert wait_end(client, timeout=2)["state"] == "stopped"  # and still stops the unheld jog
    assert not [thread for thread in started if thread.is_alive()]


def test_a_second_motion_while_one_runs_is_refused(client):
    with armed(client, NODE, "motion") as (_, header):
        assert client.post(f"{MOTION}/jog", json={"velocity": 30, "seconds": 2}, headers=header).status_code == 200
        again = client.post(f"{MOTION}/move", json={"distance": 10}, headers=header)
        assert again.status_code == 409 and "stop it first" in again.json()["detail"]
        stopped = client.post(f"{MOTION}/stop")  # anyone may stop
        assert stopped.json()["state"] == "stopped"
        assert client.get(f"{NODE}/state").json()["state"] in ("QUICK STOP ACTIVE", "SWITCH ON DISABLED")


def test_a_move_the_drive_faults_in_ends_failed_and_names_the_fault(client):
    """A linear axis (0x3360 = 1) whose software limit (0x607D,2) the move crosses: the drive faults (error 36),
    and the motion ends ``failed`` with the fault as the XtrapulsPac's manual names it, not ``stopped``."""
    here = read(client, "0x6064")
    limits = {key: read(client, key) for key in ("0x3360", "0x607D,1", "0x607D,2")}
    crossed = {"0x3360": 1, "0x607D,1": here - 100_000, "0x607D,2": here + 1000}
    try:
        for key, value in crossed.items():
            assert client.put(f"{NODE}/objects/{key}", json={"value": value}).status_code == 200
        with armed(client, NODE, "motion") as (_, header):
            started = client.post(f"{MOTION}/move", json={"distance": 2048, "velocity": 300}, headers=header)
            assert started.status_code == 200, started.text
            ended = wait_end(client, timeout=5)
        assert client.get(f"{NODE}/state").json()["state"] == "FAULT"
    finally:
        for key, value in limits.items():
            assert client.put(f"{NODE}/objects/{key}", json={"value": value}).status_code == 200
        assert client.post(f"{NODE}/faults/reset").status_code == 200
    assert ended["state"] == "failed", ended
    assert ended["reason"] == "the drive faulted: Software position limit"
