"""The REST dictionary keeps what depends on the node: a ``$NODEID`` default stays its expression (as ``eds show``
gives it) with the offset to add to a node ID, and a DCF's configured values are shown beside the defaults."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from fastapi.testclient import TestClient
from tests.support.access import admin_app, api_client
from tests.support.small_eds import write_small_eds

from servostudio.api.app import Settings
from servostudio.cli import main


@pytest.fixture
def client(tmp_path: Path) -> TestClient:
    return api_client(admin_app(Settings(projects_dir=tmp_path, user_eds_dir=tmp_path / "user-eds"), tmp_path / "data"))


def _entry(client: TestClient, device: str, index: int, sub: int = 0) -> dict:
    od = client.get(f"/api/dictionaries/{device}").json()
    return next(obj for obj in od["objects"] if obj["index"] == index)["subs"][sub]


def test_a_node_id_default_is_the_expression_as_eds_show_gives_it(client: TestClient, capsys) -> None:
    emcy = _entry(client, "xtrapulspac", 0x1014)
    assert main(["eds", "show", "xtrapulspac", "0x1014"]) == 0
    shown = json.loads(capsys.readouterr().out)
    assert emcy["default"] == shown["default"] == "$NODEID+0x80"
    assert emcy["default_node_offset"] == 0x80
    device_type = _entry(client, "xtrapulspac", 0x1000)
    assert (device_type["default"], device_type["default_node_offset"]) == (0x00020192, None)


def test_a_dcf_shows_its_configured_values(client: TestClient, tmp_path: Path) -> None:
    eds = write_small_eds(tmp_path).read_text(encoding="utf-8")
    dcf = eds.replace("DefaultValue=3000", "DefaultValue=3000\nParameterValue=1500")
    response = client.post("/api/dictionaries", files={"eds": ("cell.eds", dcf.encode())})
    assert response.status_code == 201, response.text
    speed = _entry(client, "cell", 0x2000)
    assert (speed["default"], speed["configured"], speed["configured_node_offset"]) == (3000, 1500, None)
