"""The sequence routes on the server's simulated bus: check with issues and graph, the project's SEQUENCE.TXT,
download refused whole, download + start as the armed controller, and the monitor's timeline."""

from __future__ import annotations

import time

import pytest
from tests.support.access import admin_app, api_client
from tests.support.jobs_api import armed
from tests.support.sequence_programs import COUNTER_LOOP

from servostudio.api.app import Settings

NODE = "/api/buses/sim/nodes/1"
SEQ = f"{NODE}/sequences"
BAD = "SeqNb=1\nSeqType=SPEED\nSpeed=10\nAccelTime=200000\n"


@pytest.fixture(scope="module")
def app(tmp_path_factory):
    root = tmp_path_factory.mktemp("sequences")
    return admin_app(Settings(projects_dir=root / "projects", static_dir=root / "no-ui", buses=("sim",)), root / "data")


@pytest.fixture
def client(app):
    with api_client(app) as client:
        yield client
        client.put(f"{NODE}/state", json={"target": "switch-on-disabled"})


def test_check_gives_issues_or_sequences_and_graph(client):
    bad = client.post("/api/sequences/check", json={"text": BAD}).json()
    assert bad["ok"] is False and bad["issues"][0]["line"] == 4 and bad["issues"][0]["keyword"] == "AccelTime"
    good = client.post("/api/sequences/check", json={"text": COUNTER_LOOP}).json()
    assert good["ok"] and [s["sequence"] for s in good["sequences"]] == [1, 2, 3]
    assert {(e["from"], e["to"], e["kind"]) for e in good["graph"]["edges"]} >= {(2, 1, "counter")}


def test_a_bad_download_is_refused_and_nothing_is_written(client):
    assert client.put(SEQ, json={"text": COUNTER_LOOP}).json()["verified"]
    refused = client.put(SEQ, json={"text": BAD, "store": True})
    assert refused.status_code == 422 and "SEQUENCE.TXT:4: AccelTime" in refused.json()["detail"]
    assert [s["sequence"] for s in client.get(SEQ).json()["sequences"]] == [1, 2, 3]


def test_start_needs_the_controller_and_the_timeline_shows_the_order(client):
    assert client.put(SEQ, json={"text": COUNTER_LOOP}).json()["verified"]
    assert client.post(f"{SEQ}/start", json={"sequence": 1}).status_code == 409
    client.post(f"{SEQ}/monitor?fresh=true")
    with armed(client, NODE, "control") as (_, header):
        assert client.post(f"{SEQ}/start", json={"sequence": 1}, headers=header).status_code == 200
        deadline = time.monotonic() + 15
        while True:
            snapshot = client.get(f"{SEQ}/monitor").json()
            if snapshot["executed"] and not snapshot["running"]:
                break
            assert time.monotonic() < deadline, snapshot
            time.sleep(0.05)
    assert [run["sequence"] for run in snapshot["executed"]] == [1, 2, 1, 2, 3]
    phases = [(sample["sequence"], sample["phase"]) for sample in snapshot["timeline"]]
    assert (1, "BEGIN") in phases and (3, "END") in phases and phases[-1] == (-1, "IDLE")
    client.delete(f"{SEQ}/monitor")


def test_the_conditional_input_is_written(client):
    with armed(client, NODE, "control") as (_, header):
        answer = client.put(f"{SEQ}/inputs", json={"conditional": "1......."}, headers=header).json()
    assert answer["conditional"] & 0x80
