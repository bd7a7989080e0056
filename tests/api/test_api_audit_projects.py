"""Project writes in the audit log over REST: who changed which object of which axis, from the project's previous
value to the new one, and the changes of the project itself."""

from __future__ import annotations

import pytest
from tests.support.access import admin_app, api_client

from servostudio.api.app import Settings


@pytest.fixture(scope="module")
def client(tmp_path_factory):
    root = tmp_path_factory.mktemp("audit-projects")
    app = admin_app(Settings(projects_dir=root / "projects", static_dir=root / "no-ui"), root / "data")
    (root / "projects").mkdir()
    with api_client(app) as client:
        yield client


def test_a_parameter_change_is_logged_with_the_project_s_old_value(client):
    assert (
        client.post("/api/projects", json={"name": "p", "buses": [{"name": "sim", "interface": "sim"}]}).status_code
        == 201
    )
    axis = {"name": "X", "device": "xtrapulspac", "node_id": 1, "bus": "sim"}
    assert client.post("/api/projects/p/axes", json=axis).status_code in (200, 201)
    for value in (2000, 3000):
        answer = client.put("/api/projects/p/axes/X/parameters", json={"values": {"0x6081": value}})
        assert answer.status_code == 200, answer.text
    entries = client.get("/api/audit", params={"project": "p", "action": "project_write"}).json()["entries"]
    changes = [(entry.get("object"), entry.get("old"), entry.get("new")) for entry in entries if entry.get("object")]
    assert changes[:2] == [("0x6081,0", 2000, 3000), ("0x6081,0", None, 2000)]
    assert all(entry["user"].startswith("token") and entry["project_axis"] == "X" for entry in entries[:2])
    assert {entry.get("detail") for entry in entries} >= {"created"}
