"""Input limits of the REST API: request bodies refused early with 413, drive files taken as 8-bit text (Latin-1,
empty), backup directories kept to the project store and the export directory, job states from their nodes, and
no server path in any answer."""

from __future__ import annotations

import asyncio
import time

import pytest
from tests.support.access import TEST_HOST, admin_app, api_client, token

from servostudio.api.app import Settings
from servostudio.api.limits import DEFAULT_BODY_BYTES
from servostudio.api.routes.backup import DRIVE_FILE_BYTES
from servostudio.api.routes.dictionaries import EDS_UPLOAD_BYTES
from servostudio.api.routes.projects import ARCHIVE_UPLOAD_BYTES, DCF_UPLOAD_BYTES

FILES = "/api/buses/sim/nodes/1/files"
JOB_KEYS = {"id", "operation", "state", "result", "error", "started", "finished"}


@pytest.fixture(scope="module")
def limits_app(tmp_path_factory):
    root = tmp_path_factory.mktemp("limits")
    settings = Settings(
        projects_dir=root / "projects",
        export_dir=root / "exports",
        user_eds_dir=root / "user-eds",
        static_dir=root / "no-ui",
        buses=("sim",),
    )
    app = admin_app(settings, root / "data")
    with api_client(app) as client:
        assert client.post("/api/buses/sim/scan").status_code == 200
        app.state.client = client
        app.state.token = token(root / "data")
        yield app


@pytest.fixture
def client(limits_app):
    return limits_app.state.client


def _call(app, method: str, path: str, length: int | None, chunks: list[bytes]) -> tuple[int, dict, int]:
    """One request straight to the ASGI app: (status, JSON body, how many body chunks the server read)."""
    read = 0
    sent: list[dict] = []

    async def receive() -> dict:
        nonlocal read
        if read < len(chunks):
            read += 1
            return {"type": "http.request", "body": chunks[read - 1], "more_body": read < len(chunks)}
        return {"type": "http.disconnect"}

    async def send(message: dict) -> None:
        sent.append(message)

    headers = [(b"host", TEST_HOST.encode()), (b"authorization", f"Bearer {app.state.token}".encode())]
    if length is not None:
        headers.append((b"content-length", str(length).encode()))
    scope = {
        "type": "http",
        "asgi": {"version": "3.0"},
        "http_version": "1.1",
        "method": method,
        "scheme": "http",
        "path": path,
        "raw_path": path.encode(),
        "query_string": b"",
        "root_path": "",
        "headers": headers,
        "client": ("127.0.0.1", 50000),
        "server": (TEST_HOST, 80),
    }
    asyncio.run(app(scope, receive, send))
    import json

    body = b"".join(message.get("body", b"") for message in sent if message["type"] == "http.response.body")
    return sent[0]["status"], json.loads(body), read


@pytest.mark.parametrize(
    ("method", "path", "limit"),
    [
        ("POST", "/api/dictionaries", EDS_UPLOAD_BYTES),
        ("PUT", f"{FILES}/DRIVEPAR.TXT", DRIVE_FILE_BYTES),
        ("POST", "/api/projects/unarchive", ARCHIVE_UPLOAD_BYTES),
        ("POST", "/api/projects/p/axes/X/dcf", DCF_UPLOAD_BYTES),
        ("POST", "/api/projects", DEFAULT_BODY_BYTES),
    ],
)
def test_a_declared_length_over_the_limit_is_refused_before_the_body_is_read(limits_app, method, path, limit):
    status, body, read = _call(limits_app, method, path, limit + 1, [b"x" * 10])
    assert (status, body["kind"], body["error"]) == (413, "too_large", "BodyTooLarge")
    assert f"limit of {limit} bytes" in body["detail"] and read == 0


def test_a_body_without_length_is_refused_as_soon_as_it_passes_the_limit(limits_app):
    chunk = b"x" * (64 * 1024)
    chunks = [chunk] * (ARCHIVE_UPLOAD_BYTES // len(chunk) + 50)
    status, body, read = _call(limits_app, "POST", "/api/projects/unarchive", None, chunks)
    assert (status, body["kind"]) == (413, "too_large")
    assert read == ARCHIVE_UPLOAD_BYTES // len(chunk) + 1  # not one chunk more than needed to know
    assert limits_app.state.client.get("/api/projects").json() == []


def test_an_oversized_eds_upload_keeps_nothing(client):
    files = {"eds": ("big.eds", b"[FileInfo]\n" + b";" * EDS_UPLOAD_BYTES)}
    answer = client.post("/api/dictionaries", files=files)
    assert answer.status_code == 413 and answer.json()["kind"] == "too_large"
    assert "big" not in [item["device"] for item in client.get("/api/dictionaries").json()]


def test_a_latin1_drive_file_and_an_empty_one_are_restored(client):
    text = "; réglage usine\n0x6065,0=4000 ; fenêtre de poursuite\n".encode("latin-1")
    headers = {"content-type": "text/plain"}
    accented = client.put(f"{FILES}/DRIVEPAR.TXT?store=false", content=text, headers=headers)
    assert accented.status_code == 200 and accented.json()["ok"], accented.json()
    assert accented.json()["counts"] == {"verified": 1}
    empty = client.put(f"{FILES}/DRIVEPAR.TXT?store=false", content=b"", headers=headers)
    assert empty.status_code == 200 and empty.json()["ok"] and empty.json()["counts"] == {}


def test_a_refused_upload_names_no_server_path(client, limits_app):
    answer = client.put(f"{FILES}/USER_PAR.TXT", content=b"0x6065,0=banana\n", headers={"content-type": "text/plain"})
    detail = answer.json()["detail"]
    assert answer.status_code == 422 and detail.startswith("USER_PAR.TXT:1: ")
    assert "/tmp" not in detail and str(limits_app.state.server.settings.projects_dir) not in detail


@pytest.mark.parametrize("directory", ["/etc", "{projects}/../outside", "relative/elsewhere"])
def test_a_backup_directory_outside_the_store_and_the_export_directory_is_refused(client, limits_app, directory):
    named = directory.format(projects=limits_app.state.server.settings.projects_dir)
    answer = client.post("/api/buses/sim/backup", json={"directory": named, "nodes": [1]})
    body = answer.json()
    assert (answer.status_code, body["kind"], body["error"]) == (422, "invalid_input", "DirectoryRefused")
    assert named not in body["detail"] and "/" not in body["detail"]


def _ended(client, job: dict) -> dict:
    deadline = time.monotonic() + 30
    while job["state"] == "running" and time.monotonic() < deadline:
        time.sleep(0.05)
        job = client.get(f"/api/jobs/{job['id']}").json()
    return job


def test_backup_jobs_end_done_partial_or_failed_by_their_nodes(client, limits_app):
    exports = limits_app.state.server.settings.export_dir
    start = lambda nodes: client.post(  # noqa: E731 -- one request, three node sets
        "/api/buses/sim/backup", json={"directory": str(exports / "jobs"), "nodes": nodes, "files": ["USER_PAR.TXT"]}
    ).json()
    done, partial, failed = _ended(client, start([1])), _ended(client, start([1, 42])), _ended(client, start([42]))
    assert (done["state"], partial["state"], failed["state"]) == ("done", "partial", "failed")
    assert set(done) == set(partial) == set(failed) == JOB_KEYS
    assert isinstance(partial["result"]["1"], list) and "error" in partial["result"]["42"]
    assert partial["error"].startswith("1 of 2 failed: node 42:") and failed["error"].startswith("1 of 1 failed")
    assert done["error"] is None
