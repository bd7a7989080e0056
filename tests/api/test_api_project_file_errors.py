"""A malformed project file is named by its place in the project in every answer (``p/X/DRIVEPAR.TXT:2``), never by
the server's path to the project store (issue 11: no server paths in messages)."""

from __future__ import annotations

from pathlib import Path

from tests.support.access import admin_app, api_client

from servostudio.api.app import Settings


def test_a_broken_axis_file_and_project_file_are_named_by_their_place(tmp_path: Path) -> None:
    store = tmp_path / "projects"
    client = api_client(admin_app(Settings(projects_dir=store, user_eds_dir=tmp_path / "eds"), tmp_path / "data"))
    created = client.post("/api/projects", json={"name": "p", "buses": [{"name": "sim", "interface": "sim"}]})
    axis = {"name": "X", "device": "xtrapulspac", "node_id": 1, "bus": "sim", "revision": created.json()["revision"]}
    assert client.post("/api/projects/p/axes", json=axis).status_code == 201
    (store / "p" / "X" / "DRIVEPAR.TXT").write_text("0x3051,0=1\n0x2004,0=12\n")
    answer = client.get("/api/projects/p/axes/X/parameters")
    assert answer.status_code == 422
    assert answer.json()["detail"].startswith("p/X/DRIVEPAR.TXT:2: ") and str(tmp_path) not in answer.text
    (store / "p" / "project.toml").write_text("[project\n")
    answer = client.get("/api/projects/p")
    assert answer.json()["detail"].startswith("p/project.toml:1: ") and str(tmp_path) not in answer.text
