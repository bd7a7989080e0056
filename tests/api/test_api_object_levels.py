"""The level each object needs to be written, as the dictionary payload shows it and as object writes (REST and
terminal) enforce it, on the server's embedded simulated drives. The rules (``services.users.levels``): the
oscilloscope's set-up is the Operator's, the control word and the sequence inputs the Maintenance level's,
firmware update the Administrator's, every other writable entry the Expert's; read-only entries nobody's."""

from __future__ import annotations

import pytest
from fastapi.testclient import TestClient
from tests.support.access import admin_app, bearer, token

from servostudio.services.settings import Settings
from servostudio.services.users import Level

OBJECTS = "/api/buses/sim/nodes/1/objects"
EXPECTED = {  # (index, sub) of the XtrapulsPac → level
    (0x5805, 0): "operator",  # oscilloscope pre-trigger
    (0x6040, 0): "maintenance",  # control word
    (0x3601, 1): "maintenance",  # sequence number input
    (0x60FF, 0): "expert",  # target velocity
    (0x60F9, 1): "expert",  # a speed loop gain (DRIVEPAR)
    (0x5F30, 1): "administrator",  # firmware update code
    (0x6041, 0): None,  # status word: read-only
}


@pytest.fixture(scope="module")
def app(tmp_path_factory, sim_opener):
    root = tmp_path_factory.mktemp("object-levels")
    app = admin_app(Settings(projects_dir=root / "projects", static_dir=root / "no-ui", buses=("sim",)), root / "data")
    with TestClient(app) as client:
        sim_opener(app.state.server.connections)
        yield app, client


def as_level(app, level: Level) -> dict[str, str]:
    return bearer(token(app.state.server.settings.data_dir, level))


@pytest.mark.parametrize("device", ["xtrapulspac", "cd1k", "encotrive"])
def test_the_dictionary_payload_names_the_level_of_every_entry(app, device):
    app, client = app
    dictionary = client.get(f"/api/dictionaries/{device}", headers=as_level(app, Level.OPERATOR)).json()
    for obj in dictionary["objects"]:
        for entry in obj["subs"]:
            writable = entry["access"] in ("rw", "wo", "rwr", "rww")
            assert (entry["write_level"] is not None) == writable, (obj["index"], entry)
    if device == "xtrapulspac":
        levels = {
            (obj["index"], entry["subindex"]): entry["write_level"]
            for obj in dictionary["objects"]
            for entry in obj["subs"]
        }
        assert {key: levels[key] for key in EXPECTED} == EXPECTED


def test_an_object_write_needs_the_objects_level(app):
    app, client = app
    maintenance, operator, expert = (
        as_level(app, level) for level in (Level.MAINTENANCE, Level.OPERATOR, Level.EXPERT)
    )
    below = client.put(f"{OBJECTS}/0x60FF", json={"value": 0}, headers=maintenance)
    assert below.status_code == 403 and below.json()["error"] == "LevelTooLow"
    assert "writing 0x60FF,0" in below.json()["detail"] and "needs the expert level" in below.json()["detail"]
    assert client.put(f"{OBJECTS}/0x5805", json={"value": 10}, headers=operator).status_code == 200
    assert client.put(f"{OBJECTS}/controlword", json={"value": 6}, headers=operator).status_code == 403
    assert client.put(f"{OBJECTS}/0x5F30,1", json={"value": 0}, headers=expert).status_code == 403
    assert client.get(f"{OBJECTS}/0x60FF", headers=operator).status_code == 200  # reading is everyone's


def test_a_terminal_write_needs_the_objects_level_too(app):
    app, client = app
    with client.websocket_connect("/api/ws/terminal", headers=as_level(app, Level.MAINTENANCE)) as terminal:
        terminal.send_json({"op": "write", "bus": "sim", "node": 1, "object": "0x60FF", "value": 0})
        answer = terminal.receive_json()
        assert (answer["type"], answer["kind"], answer["error"]) == ("error", "forbidden", "LevelTooLow")
        terminal.send_json({"op": "read", "items": [{"bus": "sim", "node": 1, "object": "0x60FF"}]})
        assert terminal.receive_json()["type"] == "values"
