"""What the server knows of a drive's NMT state (issue #14 point 7): the node's own heartbeat when it sends one,
else what its SDO answer proves (pre-operational or operational), never just "unknown" for a drive that answers."""

from __future__ import annotations

import time

from tests.support.access import admin_app, api_client

from servostudio.api.app import Settings

NODE = "/api/buses/sim/nodes/2"


def test_nmt_from_the_sdo_answer_then_from_the_heartbeat(tmp_path):
    app = admin_app(Settings(projects_dir=tmp_path, buses=("sim",)), tmp_path / "data")
    with api_client(app) as client:
        client.app.state.server.connections.get("sim").link.wait_connected(5.0)
        state = client.get(f"{NODE}/state").json()
        assert (state["nmt_state"], state["nmt_source"]) == (None, "sdo")
        assert state["nmt_text"] == "PRE-OPERATIONAL or OPERATIONAL (answers SDO; no heartbeat seen)"
        assert client.put(f"{NODE}/objects/0x1017", json={"value": 50}).status_code == 200
        assert client.post("/api/buses/sim/nmt", json={"command": "start", "node": 2}).status_code == 204
        state = _until(client, lambda answer: answer["nmt_source"] == "heartbeat")
        assert (state["nmt_state"], state["nmt_text"]) == ("OPERATIONAL", "OPERATIONAL")
        client.put(f"{NODE}/objects/0x1017", json={"value": 0})


def _until(client, done, timeout: float = 5.0) -> dict:
    deadline = time.monotonic() + timeout
    while True:
        answer = client.get(f"{NODE}/state").json()
        if done(answer) or time.monotonic() > deadline:
            return answer
        time.sleep(0.05)
