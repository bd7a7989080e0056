"""``drive_state`` events on /api/ws/events: a state change made behind the state routes' back (a raw control
word write) reaches the event socket through the slow status word watch."""

from __future__ import annotations

import threading
import time

from tests.support.access import admin_app, api_client

from servostudio.api.app import Settings

WAIT = 10.0


def _next_state(socket, node: int) -> dict:
    while True:
        event = socket.receive_json()
        if event["type"] == "drive_state" and event.get("node") in (node, -1):
            return event


def test_state_change_by_control_word_is_published(tmp_path):
    app = admin_app(Settings(), tmp_path)
    with api_client(app) as client:
        client.post("/api/buses", json={"spec": "sim"})
        hub = app.state.server.connections.events
        # A watchdog event ends the wait if the expected one never comes (receive_json has no timeout).
        watchdog = threading.Timer(WAIT, hub.publish, [{"type": "drive_state", "node": -1, "state": "timeout"}])
        watchdog.start()
        try:
            with client.websocket_connect("/api/ws/events?types=drive_state") as socket:
                assert client.get("/api/buses/sim/nodes/1/state").json()["state"] == "SWITCH ON DISABLED"
                first = _next_state(socket, 1)
                assert (first["bus"], first["state"]) == ("sim", "SWITCH ON DISABLED")
                written = client.put("/api/buses/sim/nodes/1/objects/controlword", json={"value": 6})  # shutdown
                assert written.status_code == 200, written.text
                event = _next_state(socket, 1)
                assert event["state"] == "READY TO SWITCH ON", event
                assert event["statusword"] & 0x6F == 0x21
                assert client.get("/api/buses/sim/nodes/1/state").json()["state"] == "READY TO SWITCH ON"
        finally:
            watchdog.cancel()


def test_no_polling_without_a_listener(tmp_path):
    app = admin_app(Settings(), tmp_path)
    with api_client(app) as client:
        client.post("/api/buses", json={"spec": "sim"})
        hub = app.state.server.connections.events
        assert not hub.wants("drive_state")
        with client.websocket_connect("/api/ws/events?types=emcy"):
            assert not hub.wants("drive_state")
        with client.websocket_connect("/api/ws/events"):
            for _ in range(500):  # the server subscribes just after accepting the socket
                if hub.wants("drive_state"):
                    break
                time.sleep(0.02)
            assert hub.wants("drive_state")
