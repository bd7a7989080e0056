"""Project buses and open buses (issue #14 point 11): one spec is one bus however it is spelt, matched by spec before
name; opening an open spec again answers explicitly (200 ``existing``, or 409 naming it under another name)."""

from __future__ import annotations

import pytest
from tests.support.access import admin_app, api_client

from servostudio.api.app import Settings


@pytest.fixture
def client(tmp_path, socketcand):
    with api_client(admin_app(Settings(projects_dir=tmp_path), tmp_path / "data")) as client:
        opened = client.post("/api/buses", json={"spec": f"{socketcand.spec}/can0", "id": "line"})
        assert (opened.status_code, opened.json()["existing"]) == (201, False)
        yield client


def test_the_same_spec_again_is_the_open_bus_said_so(client, socketcand):
    again = client.post("/api/buses", json={"spec": socketcand.spec})
    assert (again.status_code, again.json()["id"], again.json()["existing"]) == (200, "line", True)
    same_name = client.post("/api/buses", json={"spec": socketcand.spec, "id": "line"})
    assert (same_name.status_code, same_name.json()["existing"]) == (200, True)


def test_the_same_spec_under_a_new_name_is_refused_naming_the_open_bus(client, socketcand):
    refused = client.post("/api/buses", json={"spec": socketcand.spec, "id": socketcand.spec.replace(":", "-")})
    assert refused.status_code == 409
    assert "open already as bus 'line'" in refused.json()["detail"]
    assert [bus["id"] for bus in client.get("/api/buses").json()] == ["line"]


def test_project_buses_match_by_spec_first_then_by_name(client, socketcand):
    asked = [
        {"name": "socketcand-127.0.0.1", "spec": socketcand.spec},  # another name, the spec without its channel
        {"name": "line", "spec": socketcand.spec},
        {"name": "line", "spec": "virtual:elsewhere"},  # the name is open, with another spec
        {"name": "nowhere", "spec": "virtual:nowhere"},
        {"name": "bad", "spec": "nonsense"},
    ]
    answer = client.post("/api/buses/match", json={"buses": asked}).json()
    assert [(item["bus"], item["by"]) for item in answer] == [
        ("line", "spec"),
        ("line", "name"),
        ("line", "name_only"),
        (None, None),
        (None, None),
    ]
    node = client.get("/api/buses/line/nodes/1/objects/0x6041")  # the UI's calls then reach the drive
    assert node.status_code == 200 and node.json()["node"] == 1
