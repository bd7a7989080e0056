"""Node routes on a freshly opened ``sim`` bus, with no scan: the server identifies a node on first use, once even
when several requests arrive together, again when an earlier identification lost its answers; ``?device=``
names the device instead."""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import pytest
from tests.support.access import admin_app, api_client

from servostudio.api.app import Settings
from servostudio.services.bus import NodeInfo


@pytest.fixture
def fresh(tmp_path):
    """A new server with the sim bus just opened (nothing scanned)."""
    app = admin_app(Settings(), tmp_path)
    with api_client(app) as client:
        assert client.post("/api/buses", json={"spec": "sim"}).json()["nodes"] == []
        yield app, client


def _node(client, node, tail):
    return f"/api/buses/sim/nodes/{node}/{tail}"


def test_every_node_route_works_without_scan(fresh):
    _app, client = fresh
    state = client.get(_node(client, 1, "state"))
    assert state.status_code == 200, state.text
    assert state.json()["state"] == "SWITCH ON DISABLED" and state.json()["statusword"] & 0x4F == 0x40
    faults = client.get(_node(client, 2, "faults")).json()
    assert faults["fault"] is False and faults["faults"] == []
    assert client.post(_node(client, 2, "faults/reset")).json()["fault"] is False
    rows = client.post(_node(client, 3, "read"), json={"objects": ["statusword", "0x60F9,2"]}).json()
    assert [row["error"] for row in rows] == [None, None] and rows[0]["value"]["name"] == "Statusword"
    written = client.put(_node(client, 3, "objects/0x60F9,2"), json={"value": rows[1]["value"]["raw"] + 1})
    assert written.status_code == 200, written.text
    assert client.get(_node(client, 3, "objects/0x60F9,2")).json()["raw"] == rows[1]["value"]["raw"] + 1
    known = {info["node"]: info["device"] for info in client.get("/api/buses/sim").json()["nodes"]}
    assert known == {1: "xtrapulspac", 2: "xtrapulspac", 3: "xtrapulspac"}


def test_concurrent_first_requests_identify_once(fresh):
    app, client = fresh
    identified = []
    connection = app.state.server.connections.get("sim")
    original = connection.nodes.__class__.__setitem__

    class Recording(dict):
        def __setitem__(self, key, value):
            identified.append(key)
            original(self, key, value)

    connection.nodes = Recording()
    paths = [_node(client, node, tail) for node in (1, 2) for tail in ("state", "faults", "objects/statusword")] * 3
    with ThreadPoolExecutor(len(paths)) as pool:
        answers = list(pool.map(client.get, paths))
    assert [answer.status_code for answer in answers] == [200] * len(paths), [a.text for a in answers]
    assert sorted(identified) == [1, 2]


def test_a_lost_identification_is_repeated(fresh):
    app, client = fresh
    connection = app.state.server.connections.get("sim")
    connection.nodes[1] = NodeInfo(node=1)  # what identify leaves when the identity answers were lost
    answer = client.get(_node(client, 1, "state"))
    assert answer.status_code == 200, answer.text
    assert connection.nodes[1].device == "xtrapulspac" and connection.nodes[1].vendor_id is not None


def test_device_override(fresh):
    app, client = fresh
    answer = client.get(_node(client, 1, "objects/statusword"), params={"device": "xtrapulspac"})
    assert answer.status_code == 200 and answer.json()["name"] == "Statusword"
    assert app.state.server.connections.get("sim").nodes == {}  # named, so not identified
    unknown = client.get(_node(client, 1, "state"), params={"device": "no-such-device"})
    assert unknown.status_code == 422 and "unknown device 'no-such-device'" in unknown.json()["detail"]
    silent = client.get(_node(client, 9, "state"))
    assert silent.status_code == 404 and "no object dictionary known" in silent.json()["detail"]
