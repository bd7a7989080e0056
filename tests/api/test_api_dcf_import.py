"""``POST /api/projects/{name}/axes/{axis}/dcf``: an uploaded DCF's configured values become the axis's offline
values; a refused DCF changes nothing and its message names the file as uploaded, never a server path."""

from __future__ import annotations

from pathlib import Path

import pytest
from fastapi.testclient import TestClient
from tests.support.access import admin_app, api_client

from servostudio.api.app import Settings

EDS = Path(__file__).resolve().parents[2] / "eds"


@pytest.fixture
def client(tmp_path: Path) -> TestClient:
    settings = Settings(projects_dir=tmp_path / "projects", user_eds_dir=tmp_path / "eds")
    client = api_client(admin_app(settings, tmp_path / "data"))
    created = client.post("/api/projects", json={"name": "p", "buses": [{"name": "sim", "interface": "sim"}]})
    axis = {"name": "X", "device": "xtrapulspac", "node_id": 5, "bus": "sim", "revision": created.json()["revision"]}
    assert client.post("/api/projects/p/axes", json=axis).status_code == 201
    return client


def _dcf(**configured: str) -> bytes:
    """The XtrapulsPac EDS with ``ParameterValue``s (section name → value)."""
    text = (EDS / "xtrapulspac.eds").read_text(encoding="latin-1")
    for section, value in configured.items():
        text = text.replace(f"[{section}]\n", f"[{section}]\nParameterValue={value}\n", 1)
    return text.encode("latin-1")


def _upload(client: TestClient, content: bytes, **params: str):
    return client.post("/api/projects/p/axes/X/dcf", files={"dcf": ("line.dcf", content)}, params=params)


def test_an_uploaded_dcf_sets_the_axis_values(client: TestClient) -> None:
    before = client.get("/api/projects/p").json()["revision"]
    answer = _upload(client, _dcf(**{"1400sub1": "$NODEID+0x300", "1400sub2": "1", "6041": "7"}), revision=before)
    assert answer.status_code == 200, answer.text
    body = answer.json()
    assert {(row["index"], row["subindex"]): row["value"] for row in body["parameters"]} == {
        (0x1400, 1): 0x305,  # $NODEID resolved for the axis (node 5)
        (0x1400, 2): 1,
    }
    assert len(body["skipped"]) == 1 and "0x6041" in body["skipped"][0]
    assert body["revision"] != before
    assert client.get("/api/projects/p/axes/X/parameters/0x1400,2").json()["value"] == 1
    (kept, *_) = client.get("/api/projects/p/revisions").json()  # what it replaced stays restorable, with who did it
    me = client.get("/api/me").json()["name"]
    assert (kept["revision"], kept["reason"], kept["by"]) == (before, "import of line.dcf into axis X", me)


def test_a_dry_run_answers_what_would_change_and_writes_nothing(client: TestClient) -> None:
    before = client.get("/api/projects/p").json()["revision"]
    content = _dcf(**{"1400sub2": "1", "6068": "40"})
    preview = _upload(client, content, dry_run="true")
    assert preview.status_code == 200, preview.text
    changes = {(row["index"], row["subindex"]): (row["old"], row["new"]) for row in preview.json()["changes"]}
    assert changes == {(0x1400, 2): (255, 1), (0x6068, 0): (0, 40)}
    assert preview.json()["revision"] == before == client.get("/api/projects/p").json()["revision"]
    assert client.get("/api/projects/p/axes/X/parameters/0x1400,2").json()["file"] is None
    assert client.get("/api/projects/p/revisions").json() == []
    imported = _upload(client, content, revision=before).json()
    assert imported["changes"] == preview.json()["changes"] and imported["revision"] != before


def test_a_refused_dcf_names_the_uploaded_file_and_changes_nothing(client: TestClient, tmp_path: Path) -> None:
    answer = _upload(client, _dcf(**{"1400sub2": "1", "3410sub1": "25"}))
    assert answer.status_code == 422
    message = answer.json()["detail"]
    assert message.startswith("line.dcf:") and "ParameterValue 25 is outside the limits" in message
    assert str(tmp_path) not in message and "/tmp" not in message
    assert client.get("/api/projects/p/axes/X/parameters/0x1400,2").json()["file"] is None


def test_a_stale_revision_is_a_conflict(client: TestClient) -> None:
    answer = _upload(client, _dcf(**{"1400sub2": "1"}), revision="0" * 12)
    assert answer.status_code == 409
