"""An empty bus is an answer over REST: 200 with ``[]``, and ``X-Scan-Hint`` says why the bus may look empty."""

from __future__ import annotations

from pathlib import Path

from tests.support.access import admin_app, api_client

from servostudio.api.app import Settings


def test_an_empty_scan_is_200_with_the_reasons_in_a_header(tmp_path: Path) -> None:
    client = api_client(admin_app(Settings(projects_dir=tmp_path), tmp_path / "data"))
    with client:
        opened = client.post("/api/buses", json={"spec": "virtual:empty-rest-scan", "id": "empty"})
        assert opened.status_code == 201, opened.text
        response = client.post("/api/buses/empty/scan")
    assert (response.status_code, response.json()) == (200, [])
    assert "virtual channel" in response.headers["X-Scan-Hint"]


def test_a_scan_that_finds_nodes_has_no_hint(tmp_path: Path) -> None:
    client = api_client(admin_app(Settings(projects_dir=tmp_path), tmp_path / "data"))
    with client:
        assert client.post("/api/buses", json={"spec": "sim:4", "id": "four"}).status_code == 201
        response = client.post("/api/buses/four/scan")
    assert [node["node"] for node in response.json()] == [4]
    assert "X-Scan-Hint" not in response.headers
