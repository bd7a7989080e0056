"""NMT commands are judged by the motion guard and logged as writes are (issue #11): a start or a reset of an
enabled axis needs its armed controller, read back from the node's heartbeat and its CiA 402 state; the audit log
has each command, refused or sent.  And the server's settings, read-only, for administrators."""

from __future__ import annotations

import time

import pytest
from tests.support.access import admin_app, api_client
from tests.support.jobs_api import armed, finished

from servostudio.api.app import Settings
from servostudio.services.users import Level

NODE = "/api/buses/sim/nodes/1"


@pytest.fixture(scope="module")
def app(tmp_path_factory):
    root = tmp_path_factory.mktemp("nmt")
    return admin_app(Settings(projects_dir=root / "projects", static_dir=root / "no-ui", buses=("sim",)), root / "data")


def _nmt_state(client, timeout: float = 3.0) -> str | None:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        state = client.get(f"{NODE}/state").json()
        if state["nmt_source"] == "heartbeat":
            return state["nmt_state"]
        time.sleep(0.05)
    return None


def _nmt_entries(client) -> list[dict]:
    return client.get("/api/audit", params={"action": "nmt", "axis": "sim:1"}).json()["entries"]


def test_nmt_start_of_an_enabled_axis_needs_its_controller(app):
    with api_client(app) as client, client.websocket_connect("/api/ws/events?types=control") as socket:
        holder = {"X-Servo-Client": socket.receive_json()["client"]}
        assert client.put(f"{NODE}/objects/0x1017", json={"value": 50}).status_code == 200  # heartbeat: NMT read back
        assert client.post("/api/buses/sim/nmt", json={"command": "pre-operational", "node": 1}).status_code == 204
        assert client.post(f"{NODE}/control/arm", headers=holder).status_code == 200
        enabled = client.put(f"{NODE}/state", json={"target": "operation-enabled"}, headers=holder)
        assert enabled.json()["state"] == "OPERATION ENABLED", enabled.text
        try:
            for command in ("start", "reset-node"):
                refused = client.post("/api/buses/sim/nmt", json={"command": command, "node": 1})
                assert refused.status_code == 409 and refused.json()["kind"] == "refused_for_safety", refused.text
            time.sleep(0.2)
            assert _nmt_state(client) == "PRE-OPERATIONAL"
            assert client.get(f"{NODE}/state").json()["state"] == "OPERATION ENABLED"
            sent = client.post("/api/buses/sim/nmt", json={"command": "start", "node": 1}, headers=holder)
            assert sent.status_code == 204, sent.text
            deadline = time.monotonic() + 3
            while _nmt_state(client) != "OPERATIONAL" and time.monotonic() < deadline:
                time.sleep(0.05)
            assert _nmt_state(client) == "OPERATIONAL"
        finally:
            client.post(f"{NODE}/control/release", headers=holder)
            client.post("/api/buses/sim/nmt", json={"command": "pre-operational", "node": 1})
            client.put(f"{NODE}/objects/0x1017", json={"value": 0})
        results = [(entry["new"], entry["result"]) for entry in reversed(_nmt_entries(client))]
        assert ("start", "refused") in results and ("reset-node", "refused") in results
        assert results.index(("start", "ok")) > results.index(("start", "refused"))


def test_the_servers_own_nmt_start_for_a_tpdo_capture_is_judged_as_the_routes(app):
    """A TPDO capture starts a PRE-OPERATIONAL node itself: on an enabled axis that hands the axis to its RPDOs, so
    only the axis's controller's capture may; anyone else's fails before the frame is sent, and both are logged."""
    capture = {"channels": ["0x606C,0"], "period_us": 1000, "samples": 50, "source": "tpdo"}
    with api_client(app) as client, armed(client) as (_socket, holder):
        assert client.post("/api/buses/sim/nmt", json={"command": "pre-operational", "node": 1}).status_code == 204
        enabled = client.put(f"{NODE}/state", json={"target": "operation-enabled"}, headers=holder)
        assert enabled.json()["state"] == "OPERATION ENABLED", enabled.text
        try:
            refused = finished(client, client.post(f"{NODE}/scope/captures", json=capture).json()["id"])
            assert refused["state"] == "failed" and "NMT start of node 1" in refused["error"], refused
            made = finished(client, client.post(f"{NODE}/scope/captures", json=capture, headers=holder).json()["id"])
            assert made["state"] == "done", made
        finally:
            client.put(f"{NODE}/state", json={"target": "switch-on-disabled"}, headers=holder)
        results = [(entry["new"], entry["result"]) for entry in reversed(_nmt_entries(client))]
        assert results[-3:] == [("start", "refused"), ("start", "ok"), ("pre-operational", "ok")], results


def test_server_settings_for_administrators_only(app):
    with api_client(app) as client:
        shown = client.get("/api/server/settings").json()
        assert shown["buses"] == ["sim"] and shown["host"] == "127.0.0.1"
        assert shown["projects_dir"].endswith("projects") and shown["passwordless"] is False
        assert shown["audit_old_values"] == "small-writes"  # a restore logs old: null unless asked otherwise
        assert not any(word in str(shown.values()).lower() for word in ("hash", "argon", "token", "secret"))
        expert = api_client(app, Level.EXPERT)  # not entered: that would start the app a second time
        assert expert.get("/api/server/settings").status_code == 403
