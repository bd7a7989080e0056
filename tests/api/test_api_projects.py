"""REST API of projects through the FastAPI app (httpx TestClient)."""

from __future__ import annotations

import io
import zipfile
from pathlib import Path

import pytest
from fastapi.testclient import TestClient
from tests.support.access import admin_app, api_client

from servostudio.api.app import Settings


@pytest.fixture
def client(tmp_path: Path) -> TestClient:
    settings = Settings(projects_dir=tmp_path / "projects", user_eds_dir=tmp_path / "eds")
    return api_client(admin_app(settings, tmp_path / "data"))


def _project_with_axis(client: TestClient) -> str:
    created = client.post(
        "/api/projects", json={"name": "p", "buses": [{"name": "sim", "interface": "sim", "bitrate": 1000000}]}
    )
    assert created.status_code == 201
    added = client.post(
        "/api/projects/p/axes",
        json={"name": "X", "device": "xtrapulspac", "node_id": 1, "bus": "sim", "revision": created.json()["revision"]},
    )
    assert added.status_code == 201
    return added.json()["revision"]


def test_project_lifecycle(client: TestClient):
    _project_with_axis(client)
    assert [p["name"] for p in client.get("/api/projects").json()] == ["p"]
    project = client.get("/api/projects/p").json()
    assert project["axes"] == [
        {
            "name": "X",
            "device": "xtrapulspac",
            "node_id": 1,
            "bus": "sim",
            "description": "",
            "motor": "",
            "application": "",
        }
    ]
    assert client.post("/api/projects/p/rename", json={"new_name": "q"}).status_code == 200
    assert client.post("/api/projects/q/duplicate", json={"new_name": "r"}).status_code == 201
    assert client.patch("/api/projects/r/axes/X", json={"node_id": 2}).json()["axes"][0]["node_id"] == 2
    assert client.delete("/api/projects/q").status_code == 204
    assert [p["name"] for p in client.get("/api/projects").json()] == ["r"]
    assert client.delete("/api/projects/r/axes/X").json()["axes"] == []


def test_errors_carry_kind_and_message(client: TestClient):
    revision = _project_with_axis(client)
    missing = client.get("/api/projects/nope")
    assert missing.status_code == 404 and missing.json()["error"] == "ProjectNotFound"
    clash = client.post(
        "/api/projects/p/axes", json={"name": "Y", "device": "xtrapulspac", "node_id": 65, "bus": "sim"}
    )
    assert clash.status_code == 422 and "out of range 1-63" in clash.json()["detail"]
    client.put("/api/projects/p/axes/X/parameters", json={"values": {"0x3051": 1}})
    stale = client.put("/api/projects/p/axes/X/parameters", json={"values": {"0x3051": 2}, "revision": revision})
    assert stale.status_code == 409 and stale.json()["error"] == "ConflictError"


def test_offline_parameters_and_compare(client: TestClient):
    revision = _project_with_axis(client)
    written = client.put(
        "/api/projects/p/axes/X/parameters", json={"values": {"0x6060": "Sequence", "0x3051": 3}, "revision": revision}
    )
    assert written.status_code == 200
    assert [(p["name"], p["value"], p["file"]) for p in written.json()["parameters"]] == [
        ("0x6060,0 Modes of operation", -3, "DRIVEPAR.TXT"),
        ("0x3051,0 Digital inputs polarity", 3, "DRIVEPAR.TXT"),
    ]
    refused = client.put("/api/projects/p/axes/X/parameters", json={"values": {"0x6041": 1}})
    assert refused.status_code == 422 and "read-only" in refused.json()["detail"]
    one = client.get("/api/projects/p/axes/X/parameters/0x3051").json()
    assert (one["value"], one["default"], one["differs_from_default"]) == (3, 0, True)
    compare = client.get("/api/projects/p/axes/X/compare", params={"only_differences": True}).json()
    assert [(row["index"], row["values"]) for row in compare["rows"]] == [
        (0x3051, {"project": 3, "default": 0}),
        (0x6060, {"project": -3, "default": None}),
    ]
    reset = client.post("/api/projects/p/axes/X/parameters/reset", json={"addresses": ["0x3051"]})
    assert reset.json()["parameters"][0]["file"] is None


def test_templates_motors_dcf(client: TestClient):
    _project_with_axis(client)
    templates = client.get("/api/device-templates", params={"device": "xtrapulspac"}).json()
    assert [t["key"] for t in templates] == ["analog-speed", "positioner", "stepper-emulation", "expert"]
    applied = client.post("/api/projects/p/axes/X/application", json={"template": "analog-speed"}).json()
    assert applied["project"]["axes"][0]["application"] == "analog-speed"
    assert client.get("/api/projects/p/axes/X/application").json()["key"] == "analog-speed"
    motor = {"reference": "TEST-M", "motor_data": {"max_speed": 3000, "pole_pairs": 3}, "source": "test data"}
    assert client.post("/api/motors", json=motor).status_code == 201
    assert [m["reference"] for m in client.get("/api/motors").json()] == ["TEST-M"]
    chosen = client.post("/api/projects/p/axes/X/motor", json={"reference": "TEST-M"}).json()
    assert {(row["index"], row["subindex"], row["value"]) for row in chosen["changed"]} == {
        (0x6410, 7, 3000),
        (0x6080, 0, 3000),
        (0x6410, 14, 3),
        (0x3410, 1, 3),
    }
    assert client.delete("/api/motors/TEST-M").status_code == 204
    assert client.get("/api/motors").json() == []
    assert client.delete("/api/motors/TEST-M").json()["error"] == "ProjectNotFound"
    dcf = client.get("/api/projects/p/axes/X/dcf")
    assert dcf.status_code == 200 and dcf.headers["content-disposition"] == 'attachment; filename="X.dcf"'
    lines = dcf.text.splitlines()
    assert lines[lines.index("[DeviceComissioning]") + 1] == "NodeID=1"


def test_archive_download_and_upload(client: TestClient):
    _project_with_axis(client)
    client.put("/api/projects/p/axes/X/parameters", json={"values": {"0x3051": 3}})
    archive = client.get("/api/projects/p/archive")
    assert archive.status_code == 200 and archive.headers["content-type"] == "application/zip"
    names = zipfile.ZipFile(io.BytesIO(archive.content)).namelist()
    assert names == ["p/X/DRIVEPAR.TXT", "p/X/SEQUENCE.TXT", "p/X/USER_PAR.TXT", "p/project.toml"]
    restored = client.post(
        "/api/projects/unarchive",
        params={"new_name": "copy"},
        content=archive.content,
        headers={"content-type": "application/zip"},
    )
    assert restored.status_code == 201 and restored.json()["name"] == "copy"
    value = client.get("/api/projects/copy/axes/X/parameters/0x3051").json()["value"]
    assert value == 3
    evil = io.BytesIO()
    with zipfile.ZipFile(evil, "w") as writer:
        writer.writestr("../escape/project.toml", "[project]\nformat = 1\n")
    refused = client.post("/api/projects/unarchive", content=evil.getvalue())
    assert refused.status_code == 422 and "path traversal" in refused.json()["detail"]


def test_a_broken_project_is_listed_with_its_error(client: TestClient, tmp_path: Path):
    _project_with_axis(client)
    broken = tmp_path / "projects" / "broken"
    broken.mkdir()
    (broken / "project.toml").write_text("[project]\nformat = 2\n")
    listed = {p["name"]: p for p in client.get("/api/projects").json()}
    assert listed["p"]["error"] is None and listed["p"]["axis_count"] == 1
    assert listed["broken"]["error"].endswith("project.toml:2: format 2 is not supported (expected 1)")
