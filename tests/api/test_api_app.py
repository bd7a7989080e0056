"""The communication server's HTTP surface: health, OpenAPI, docs, UI."""

import httpx
from tests.support.access import admin_app, api_client

from servostudio import __version__
from servostudio.api.app import Settings


def test_health_over_real_http(live_server) -> None:
    response = httpx.get(f"{live_server.url}/api/health")
    assert response.status_code == 200
    assert response.json() == {"status": "ok", "version": __version__}


def test_openapi_and_docs_are_served(live_server) -> None:
    schema = httpx.get(f"{live_server.url}/openapi.json").json()
    assert schema["info"]["title"] == "Servo Studio"
    assert "/api/health" in schema["paths"]
    docs = httpx.get(f"{live_server.url}/docs")
    assert docs.status_code == 200 and "swagger" in docs.text.lower()


def test_ui_index_is_served_at_root(live_server) -> None:
    page = httpx.get(f"{live_server.url}/")
    assert page.status_code == 200
    assert "<title>Servo Studio</title>" in page.text


def test_static_fallback_never_escapes_the_static_dir(tmp_path) -> None:
    static = tmp_path / "static"
    static.mkdir()
    (static / "index.html").write_text("<title>shell</title>")
    (tmp_path / "secret.txt").write_text("top secret")
    client = api_client(admin_app(Settings(projects_dir=tmp_path, static_dir=static), tmp_path / "data"))
    response = client.get("/..%2Fsecret.txt")
    assert "top secret" not in response.text
    assert "<title>shell</title>" in response.text


def test_missing_ui_build_says_how_to_build_it(tmp_path) -> None:
    client = api_client(admin_app(Settings(projects_dir=tmp_path, static_dir=tmp_path / "none"), tmp_path / "data"))
    response = client.get("/")
    assert response.status_code == 503
    assert "make run" in response.text
