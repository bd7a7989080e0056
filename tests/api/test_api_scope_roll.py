"""Live roll mode through the API (docs/scope.md §8): 4 channels at 1 kHz for 20 s, every sample over the roll's
WebSocket in sequence, none lost but where a gap says so, and the recorded capture holds every one up to a gap; an
over-subscribed roll is refused with 422 before anything is armed; the socket's stop message needs its level."""

from __future__ import annotations

import pytest
from tests.support.access import admin_app, api_client
from tests.support.sync_probe import tpdo_configuration

from servostudio.services.settings import Settings

SCOPE = "/api/buses/sim/nodes/1/scope"
FOUR = ["0x6064,0", "0x606C,0", "0x6041,0", "0x6078,0"]


@pytest.fixture(scope="module")
def client(tmp_path_factory, sim_opener):
    root = tmp_path_factory.mktemp("api-roll")
    app = admin_app(Settings(projects_dir=root / "store", static_dir=root / "no-ui", buses=["sim"]), root / "data")
    with api_client(app) as test_client:
        sim_opener(app.state.server.connections)
        yield test_client


def test_four_channels_at_1_khz_for_20_s_arrive_whole_and_in_sequence(client):
    started = client.post(f"{SCOPE}/roll", json={"channels": FOUR, "period_us": 1000, "seconds": 20, "record": True})
    assert started.status_code == 202, started.text
    body = started.json()
    assert body["plan"]["stream"]["frames_per_s"] == 3000 and body["job"]["operation"] == "scope-roll"
    numbers: list[int] = []
    gaps: list[dict] = []
    values: list[list] = [[] for _ in FOUR]
    with client.websocket_connect(body["socket"]) as socket:
        while (event := socket.receive_json())["type"] != "end":
            if event["type"] == "gap":
                gaps.append(event)
                continue
            assert event["type"] == "samples", event  # no error
            numbers += range(event["seq"], event["seq"] + event["count"])
            for column, received in zip(values, event["values"], strict=True):
                column += received
    lost = [n for gap in gaps for n in range(gap["from"], gap["to"])]
    # every sample of 20 s at 1 kHz, in order; one lost only where a gap says so — a host too loaded to run the
    # simulated drives for a second makes one (the bench measures zero on a quiet host), never a silent hole
    assert numbers == sorted(numbers) and sorted(numbers + lost) == list(range(20_000))
    assert all("SYNC unanswered" in gap["reason"] for gap in gaps) and len(lost) < 2_000, gaps
    assert event["samples"] == len(numbers) and event["lost"] == len(lost)
    assert event["gaps"] == [{key: gap[key] for key in ("from", "to", "reason")} for gap in gaps]
    made = client.get(f"{SCOPE}/captures/{event['capture']}").json()
    whole = gaps[0]["from"] if gaps else 20_000  # record while rolling: every sample up to the first gap
    assert made["samples"] == whole and made["source"] == "tpdo"
    assert made["values"] == [column[:whole] for column in values]


def test_an_over_subscribed_roll_is_refused_before_anything_is_armed(client):
    drive = client.app.state.server.connections.get("sim").drive(1)
    before = tpdo_configuration(drive)
    five = client.post(f"{SCOPE}/roll", json={"channels": [*FOUR, "0x6062,0"]})
    assert five.status_code == 422 and "up to 4 channels per axis" in five.json()["detail"]
    fast = client.post(f"{SCOPE}/roll", json={"channels": FOUR, "period_us": 500})
    assert fast.status_code == 422 and "1000 µs at the fastest" in fast.json()["detail"]
    assert tpdo_configuration(drive) == before
