"""One SYNC producer per bus (docs/scope.md §8): while a roll sends the bus's SYNC, a second roll or a TPDO capture
on another node of the bus is refused with 409 and the reason (each drive would answer both producers' SYNCs, and
no capture's samples would be one per period); the running roll loses nothing; a capture by the recorder goes on.
A roll without end stops when its last reader leaves."""

from __future__ import annotations

import time

import pytest
from tests.support.access import admin_app, api_client

from servostudio.services.settings import Settings

NODES = "/api/buses/sim/nodes"
TWO = ["0x6041,0", "0x6078,0"]


@pytest.fixture(scope="module")
def client(tmp_path_factory, sim_opener):
    root = tmp_path_factory.mktemp("api-sync")
    app = admin_app(Settings(projects_dir=root / "store", static_dir=root / "no-ui", buses=["sim"]), root / "data")
    with api_client(app) as test_client:
        sim_opener(app.state.server.connections)
        yield test_client


def test_a_second_sync_producer_on_the_bus_is_refused_while_a_roll_runs(client):
    started = client.post(f"{NODES}/1/scope/roll", json={"channels": TWO, "seconds": 3})
    assert started.status_code == 202, started.text
    roll = started.json()
    with client.websocket_connect(roll["socket"]) as socket:
        first = socket.receive_json()
        assert first["type"] == "samples"
        second = client.post(f"{NODES}/2/scope/roll", json={"channels": TWO})
        assert second.status_code == 409 and "one SYNC producer per bus" in second.json()["detail"], second.text
        tpdo = client.post(f"{NODES}/3/scope/captures", json={"channels": TWO, "period_us": 1000, "source": "tpdo"})
        assert tpdo.status_code == 409 and roll["job"]["id"] in tpdo.json()["detail"]
        recorder = client.post(f"{NODES}/3/scope/captures", json={"channels": TWO, "samples": 100})
        assert recorder.status_code == 202, recorder.text  # the recorder needs no SYNC
        while (event := socket.receive_json())["type"] != "end":
            assert event["type"] == "samples", event
    assert event["lost"] == 0 and event["samples"] == 3000
    after = client.post(f"{NODES}/2/scope/roll", json={"channels": TWO, "seconds": 0.5})
    assert after.status_code == 202, after.text  # the SYNC is free again
    with client.websocket_connect(after.json()["socket"]) as socket:
        while socket.receive_json()["type"] != "end":
            pass


def test_an_endless_roll_ends_when_its_last_socket_closes(client):
    started = client.post(f"{NODES}/1/scope/roll", json={"channels": TWO})  # no seconds: until stopped
    assert started.status_code == 202, started.text
    job = started.json()["job"]["id"]
    with client.websocket_connect(started.json()["socket"]) as first:
        with client.websocket_connect(started.json()["socket"]) as second:
            assert second.receive_json()["type"] == "samples"
        assert first.receive_json()["type"] == "samples"  # one reader left: the roll goes on for the other
        assert client.get(f"/api/jobs/{job}").json()["state"] == "running"
    deadline = time.monotonic() + 10
    while (state := client.get(f"/api/jobs/{job}").json()["state"]) == "running":
        assert time.monotonic() < deadline, "the roll outlived its last reader"
        time.sleep(0.05)
    assert state in ("done", "cancelled")
    assert client.post(f"{NODES}/2/scope/roll", json={"channels": TWO, "seconds": 0.2}).status_code == 202
