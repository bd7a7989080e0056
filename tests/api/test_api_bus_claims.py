"""One claims registry per bus (services/bus/claims.py): a roll and a frequency response both borrow the node's PDOs
and send the bus's SYNC, so while one runs the other is refused with 409 naming it — and the one running goes on
untouched."""

from __future__ import annotations

import pytest
from tests.support.access import admin_app, api_client
from tests.support.jobs_api import armed, finished

from servostudio.services.settings import Settings

NODES = "/api/buses/sim/nodes"
TWO = ["0x6041,0", "0x6078,0"]
QUICK = {"loop": "plant", "periods": 2, "base_speed_rad_s": 10.0, "position_window": 20.0}


@pytest.fixture(scope="module")
def client(tmp_path_factory, sim_opener):
    root = tmp_path_factory.mktemp("api-claims")
    app = admin_app(Settings(projects_dir=root / "store", static_dir=root / "no-ui", buses=["sim"]), root / "data")
    with api_client(app) as test_client:
        sim_opener(app.state.server.connections)
        yield test_client


def test_a_frequency_response_is_refused_while_a_roll_holds_the_node(client):
    started = client.post(f"{NODES}/1/scope/roll", json={"channels": TWO, "seconds": 1.5})
    assert started.status_code == 202, started.text
    roll = started.json()["job"]["id"]
    with client.websocket_connect(started.json()["socket"]) as socket:
        assert socket.receive_json()["type"] == "samples"
        with armed(client) as (_, header):
            refused = client.post(f"{NODES}/1/frequency-response", json=QUICK, headers=header)
        assert refused.status_code == 409 and refused.json()["kind"] == "conflict", refused.text
        assert f"scope-roll {roll}" in refused.json()["detail"]
        while (event := socket.receive_json())["type"] != "end":
            assert event["type"] == "samples", event
    assert event["lost"] == 0 and event["samples"] == 1500  # the roll lost nothing
    assert client.get(f"{NODES}/1/objects/0x1603,0").json()["raw"] == 0  # no RPDO borrowed by the refused one


def test_a_roll_and_a_tpdo_capture_are_refused_while_a_frequency_response_runs(client):
    with armed(client) as (_, header):
        started = client.post(f"{NODES}/1/frequency-response", json=QUICK, headers=header)
        assert started.status_code == 202, started.text
        job = started.json()["id"]
        roll = client.post(f"{NODES}/1/scope/roll", json={"channels": TWO, "seconds": 1})
        assert roll.status_code == 409 and f"frequency-response {job}" in roll.json()["detail"], roll.text
        assert "node 1" in roll.json()["detail"]
        other = client.post(f"{NODES}/2/scope/captures", json={"channels": TWO, "period_us": 1000, "source": "tpdo"})
        assert other.status_code == 409 and "one SYNC producer per bus" in other.json()["detail"], other.text
        assert job in other.json()["detail"]
        recorder = client.post(f"{NODES}/2/scope/captures", json={"channels": TWO, "samples": 100})
        assert recorder.status_code == 202, recorder.text  # another node's recorder needs no SYNC
        assert client.post(f"/api/jobs/{job}/cancel").status_code == 200
        assert finished(client, job)["state"] in ("cancelled", "done")
    after = client.post(f"{NODES}/1/scope/roll", json={"channels": TWO, "seconds": 0.2})
    assert after.status_code == 202, after.text  # node and SYNC are free again
    with client.websocket_connect(after.json()["socket"]) as socket:
        while socket.receive_json()["type"] != "end":
            pass
