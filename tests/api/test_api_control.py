"""One controller per axis over REST and the event socket: arm, see who holds it, ask for it, release it, take it
over (Expert, logged), and the quick stop when the holder goes away — each read back from the simulated drive and
from the audit log (``GET /api/audit``, exports)."""

from __future__ import annotations

import contextlib
import csv
import io
import json
from collections.abc import Iterator

import pytest
from tests.support.access import admin_app, api_client
from tests.support.waits import eventually

from servostudio.api.app import Settings
from servostudio.services.users import Level

NODE = "/api/buses/sim/nodes/1"


@pytest.fixture(scope="module")
def app(tmp_path_factory):
    root = tmp_path_factory.mktemp("control")
    return admin_app(Settings(projects_dir=root / "projects", static_dir=root / "no-ui", buses=("sim",)), root / "data")


@pytest.fixture
def client(app):
    with api_client(app) as client:
        yield client
        client.put(f"{NODE}/state", json={"target": "switch-on-disabled"})


@contextlib.contextmanager
def live(client, types: str = "control,control_request") -> Iterator[tuple[object, dict[str, str]]]:
    """An event socket (a live client) and the header naming it."""
    with client.websocket_connect(f"/api/ws/events?types={types}") as socket:
        yield socket, {"X-Servo-Client": socket.receive_json()["client"]}


def second_user(app, level: Level):
    """Another caller of the running app (not entered as a context: that would start the app a second time)."""
    return api_client(app, level)


def state(client) -> str:
    return client.get(f"{NODE}/state").json()["state"]


def test_arm_shows_the_holder_and_release_frees_the_axis(client):
    assert client.get(f"{NODE}/control").json()["holder"] is None
    with live(client) as (socket, a):
        armed = client.post(f"{NODE}/control/arm", headers=a).json()
        assert armed["holder"]["client"] == a["X-Servo-Client"]
        assert socket.receive_json()["event"] == "armed"
        assert [(item["bus"], item["node"]) for item in client.get("/api/control").json()] == [("sim", 1)]
        assert client.post(f"{NODE}/control/arm", headers=a).status_code == 200  # arming again is no change
        assert client.post(f"{NODE}/control/release", headers=a).json()["holder"] is None
        assert socket.receive_json()["event"] == "released"
    assert client.get("/api/control").json() == []


def test_arming_needs_a_live_client_of_the_caller(client, app):
    assert "live client" in client.post(f"{NODE}/control/arm").json()["detail"]
    other = second_user(app, Level.EXPERT)
    with live(client) as (_, a):
        stolen = other.post(f"{NODE}/control/arm", headers=a)  # another user's client id is not theirs to use
        assert stolen.status_code == 409 and "live client" in stolen.json()["detail"]


def test_asking_for_an_axis_asks_its_holder_only(client):
    with live(client) as (a_socket, a), live(client) as (b_socket, b):
        client.post(f"{NODE}/control/arm", headers=a)
        assert a_socket.receive_json()["event"] == "armed"
        assert b_socket.receive_json()["event"] == "armed"
        asked = client.post(f"{NODE}/control/request", headers=b).json()
        assert [item["client"] for item in asked["requests"]] == [b["X-Servo-Client"]]
        request = a_socket.receive_json()
        assert request["type"] == "control_request" and request["from"]["client"] == b["X-Servo-Client"]
        assert client.post(f"{NODE}/control/release", headers=b).status_code == 409  # not B's to release
        client.post(f"{NODE}/control/release", headers=a)
        freed = b_socket.receive_json()  # B heard no request addressed to A: the next event is the release
        assert (freed["type"], freed["event"]) == ("control", "released")
        assert client.post(f"{NODE}/control/arm", headers=b).json()["holder"]["client"] == b["X-Servo-Client"]


def test_an_expert_takes_over_explicitly_and_lower_levels_may_not(client, app):
    with live(client) as (a_socket, a):
        client.post(f"{NODE}/control/arm", headers=a)
        client.put(f"{NODE}/state", json={"target": "operation-enabled"}, headers=a)
        assert a_socket.receive_json()["event"] == "armed"
        maintenance, expert = second_user(app, Level.MAINTENANCE), second_user(app, Level.EXPERT)
        with live(maintenance) as (_, m):
            assert maintenance.post(f"{NODE}/control/take-over", headers=m).status_code == 403
        with live(expert) as (_, e):
            taken = expert.post(f"{NODE}/control/take-over", headers=e).json()
            assert taken["holder"]["client"] == e["X-Servo-Client"]
            told = a_socket.receive_json()
            assert told["event"] == "taken_over" and told["previous"]["client"] == a["X-Servo-Client"]
            assert state(client) == "OPERATION ENABLED"  # a take-over keeps the axis as it is
            velocity = client.put(f"{NODE}/objects/target_velocity", json={"value": 10}, headers=a)
            assert velocity.status_code == 409  # A is no longer the controller
            assert expert.put(f"{NODE}/objects/target_velocity", json={"value": 0}, headers=e).status_code == 200
        # the expert's socket closed: the axis it held stopped
        eventually(lambda: state(client) != "OPERATION ENABLED", 10.0)
    taken_over = client.get("/api/audit", params={"axis": "sim:1", "action": "take_over"}).json()["entries"][0]
    assert taken_over["client"] == e["X-Servo-Client"] and a["X-Servo-Client"] in taken_over["detail"]


def test_the_holder_s_loss_quick_stops_the_axis_and_is_logged(client):
    with live(client) as (_, a):
        client.post(f"{NODE}/control/arm", headers=a)
        assert client.put(f"{NODE}/state", json={"target": "operation-enabled"}, headers=a).status_code == 200
    eventually(lambda: state(client) in ("QUICK STOP ACTIVE", "SWITCH ON DISABLED"), 10.0)
    eventually(lambda: _actions(client)[:1] == ["quick_stop"], 10.0)
    stop = client.get("/api/audit", params={"action": "quick_stop", "limit": 1}).json()["entries"][0]
    assert stop["user"] == "server" and a["X-Servo-Client"] in stop["detail"] and stop["result"] == "ok"
    assert {"arm", "enable"} <= set(_actions(client))


def test_release_of_an_enabled_axis_stops_it(client):
    with live(client) as (_, a):
        client.post(f"{NODE}/control/arm", headers=a)
        client.put(f"{NODE}/state", json={"target": "operation-enabled"}, headers=a)
        client.post(f"{NODE}/control/release", headers=a)
        assert state(client) in ("QUICK STOP ACTIVE", "SWITCH ON DISABLED")


def test_anyone_may_stop_an_axis_another_client_enabled(client, app):
    with live(client) as (_, a):
        client.post(f"{NODE}/control/arm", headers=a)
        client.put(f"{NODE}/state", json={"target": "operation-enabled"}, headers=a)
        stopped = second_user(app, Level.MAINTENANCE).put(f"{NODE}/state", json={"target": "quick-stop-active"})
        assert stopped.status_code == 200 and stopped.json()["state"] in ("QUICK STOP ACTIVE", "SWITCH ON DISABLED")


def test_every_write_is_in_the_audit_log_with_old_and_new_values(client):
    before = client.get(f"{NODE}/objects/0x60F9,2").json()["raw"]
    client.put(f"{NODE}/objects/0x60F9,2", json={"value": before + 1})
    client.put(f"{NODE}/objects/0x60F9,2", json={"value": before})
    page = client.get("/api/audit", params={"axis": "sim:1", "action": "drive_write", "limit": 2}).json()
    assert page["total"] >= 2
    newest, older = page["entries"]
    assert (older["old"], older["new"], newest["old"], newest["new"]) == (before, before + 1, before + 1, before)
    assert newest["object"] == "0x60F9,2" and newest["result"] == "ok" and newest["user"].startswith("token")
    exported = client.get("/api/audit/export", params={"format": "csv", "axis": "sim:1", "action": "drive_write"})
    assert exported.headers["content-type"].startswith("text/csv")
    assert list(csv.DictReader(io.StringIO(exported.text)))[-1]["new"] == str(before)
    lines = client.get("/api/audit/export", params={"action": "drive_write"}).text.splitlines()
    assert json.loads(lines[-1])["new"] == before
    assert client.get("/api/audit", params={"since": "yesterday"}).status_code == 422


def _actions(client) -> list[str]:
    return [entry["action"] for entry in client.get("/api/audit", params={"axis": "sim:1"}).json()["entries"]]
