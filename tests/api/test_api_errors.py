"""The error contract over real HTTP: each kind of the taxonomy answers its status with `{detail, error, kind}`, a
malformed request is 422 with FastAPI's problem list, and anything else — a bug — is a logged 500 quoting the
request id (never a 422). The kind → status table itself is `servostudio.errors.OUTCOMES`."""

from __future__ import annotations

import logging

import pytest
from fastapi.testclient import TestClient
from tests.support.access import admin_app, api_client, bearer, token

import servostudio.cli
from servostudio.api.app import Settings, create_app
from servostudio.api.errors import REQUEST_ID_HEADER
from servostudio.api.routes import buses as bus_routes
from servostudio.api.routes import projects as project_routes
from servostudio.errors import OUTCOMES, ErrorKind, ServoStudioError
from servostudio.services.users import Level

SILENT = "/api/buses/sim/nodes/42"  # no drive answers there; ?device= gives it a dictionary all the same


@pytest.fixture(scope="module")
def client(tmp_path_factory):
    root = tmp_path_factory.mktemp("errors")
    app = admin_app(Settings(projects_dir=root / "projects", static_dir=root / "no-ui", buses=("sim",)), root / "data")
    with api_client(app) as client:
        yield client


def refusal(response, status: int, kind: ErrorKind, error: str) -> str:
    """Assert the refusal and return its detail."""
    body = response.json()
    assert (response.status_code, body["kind"], body["error"]) == (status, kind, error), body
    assert OUTCOMES[kind].http_status == status
    return body["detail"]


def test_not_found(client):
    assert "no bus 'nope'" in refusal(client.get("/api/buses/nope"), 404, ErrorKind.NOT_FOUND, "UnknownBusOrNode")
    assert "no job" in refusal(client.get("/api/jobs/job999999"), 404, ErrorKind.NOT_FOUND, "UnknownJob")


def test_invalid_input_that_used_to_be_a_bare_value_error(client):
    answer = client.post("/api/buses/sim/nmt", json={"command": "jump", "node": 1})
    assert "unknown NMT command 'jump'" in refusal(answer, 422, ErrorKind.INVALID_INPUT, "InvalidInput")
    answer = client.put("/api/buses/sim/nodes/1/state", json={"target": "dancing"})
    assert "unknown CiA 402 state" in refusal(answer, 422, ErrorKind.INVALID_INPUT, "InvalidInput")


def test_malformed_request_keeps_fastapis_problem_list(client):
    body = client.post("/api/buses", json={}).json()
    assert (body["error"], body["kind"]) == ("RequestValidationError", "invalid_input")
    assert body["detail"][0]["loc"] == ["body", "spec"]


def test_too_large(client):
    answer = client.post("/api/projects/unarchive", content=bytes(project_routes.ARCHIVE_UPLOAD_BYTES + 1))
    detail = refusal(answer, 413, ErrorKind.TOO_LARGE, "BodyTooLarge")
    assert f"limit of {project_routes.ARCHIVE_UPLOAD_BYTES} bytes" in detail


def test_conflict(client):
    assert client.post("/api/projects", json={"name": "twice"}).status_code == 201
    refusal(client.post("/api/projects", json={"name": "twice"}), 409, ErrorKind.CONFLICT, "ProjectExists")


def test_refused_for_safety(client):
    answer = client.put("/api/buses/sim/nodes/1/state", json={"target": "operation-enabled"})
    assert "live client" in refusal(answer, 409, ErrorKind.REFUSED_FOR_SAFETY, "NoLiveClient")


def test_timeout(client):
    answer = client.get(f"{SILENT}/objects/0x1000", params={"device": "xtrapulspac"})
    refusal(answer, 504, ErrorKind.TIMEOUT, "SdoTimeoutError")


def test_communication(client):
    answer = client.get(f"{SILENT}/files/DRIVEPAR.TXT", params={"device": "xtrapulspac"})
    assert "no file written" in refusal(answer, 502, ErrorKind.COMMUNICATION, "BackupError")


def test_unavailable(client):
    assert client.post("/api/buses", json={"spec": "socketcand:127.0.0.1:9", "id": "gone"}).status_code == 201
    answer = client.get("/api/buses/gone/nodes/1/objects/0x1000", params={"device": "xtrapulspac"})
    refusal(answer, 503, ErrorKind.UNAVAILABLE, "SdoLinkError")
    assert client.delete("/api/buses/gone").status_code == 204


def test_unauthenticated_forbidden_and_rate_limited(client):
    anonymous = TestClient(client.app)
    refusal(anonymous.get("/api/buses"), 401, ErrorKind.UNAUTHENTICATED, "NotLoggedIn")
    operator = bearer(token(client.app.state.server.settings.data_dir, Level.OPERATOR))
    answer = client.post("/api/buses/sim/nmt", json={"command": "start", "node": 1}, headers=operator)
    assert "needs the expert level" in refusal(answer, 403, ErrorKind.FORBIDDEN, "LevelTooLow")
    for _ in range(5):
        anonymous.post("/api/session", json={"name": "nobody", "password": "wrong"})
    answer = anonymous.post("/api/session", json={"name": "nobody", "password": "wrong"})
    refusal(answer, 429, ErrorKind.RATE_LIMITED, "TooManyLogins")


@pytest.mark.parametrize("bug", [ValueError("a programming error"), KeyError("missing")])
def test_a_bug_is_a_logged_500_with_the_request_id(client, monkeypatch, caplog, bug):
    """A ValueError of a bug is not the caller's bad input: 500, logged with its traceback, never 422."""

    def broken(connection):
        raise bug

    monkeypatch.setattr(bus_routes, "scan", broken)
    with caplog.at_level(logging.ERROR, logger="servostudio.api.errors"):
        answer = client.post("/api/buses/sim/scan")
    body = answer.json()
    request_id = answer.headers[REQUEST_ID_HEADER]
    assert (answer.status_code, body["kind"], body["error"]) == (500, "internal", type(bug).__name__)
    assert body["request_id"] == request_id and request_id in body["detail"]
    assert "a programming error" not in body["detail"]  # the message stays in the server log
    record = next(record for record in caplog.records if request_id in record.getMessage())
    assert record.exc_info is not None and record.exc_info[1] is bug


def test_every_response_carries_a_request_id(client):
    first, second = client.get("/api/health"), client.get("/api/buses/nope")
    assert first.headers[REQUEST_ID_HEADER] != second.headers[REQUEST_ID_HEADER]


def test_the_terminal_sends_the_same_error_fields_and_stays_open(client):
    with client.websocket_connect("/api/ws/terminal") as socket:
        socket.send_json({"op": "write", "bus": "nope", "node": 1, "object": "0x6060", "value": 1})
        assert socket.receive_json() == {
            "type": "error",
            "detail": "no bus 'nope' (open buses: sim)",
            "error": "UnknownBusOrNode",
            "kind": "not_found",
        }
        socket.send_json({"op": "write", "bus": "sim", "node": "one"})
        assert socket.receive_json()["error"] == "TerminalError"
        socket.send_json({"op": "read", "items": [{"bus": "sim", "node": 1, "object": "statusword"}]})
        assert socket.receive_json()["type"] == "values"


def test_openapi_declares_the_error_body():
    schema = create_app(Settings(buses=())).openapi()
    assert set(schema["components"]["schemas"]["ErrorBody"]["properties"]) == {"detail", "error", "kind", "request_id"}
    responses = schema["paths"]["/api/buses/{bus}/nodes/{node}/objects/{key}"]["get"]["responses"]
    assert {"404", "409", "422", "500", "502", "503", "504"} <= set(responses)
    assert responses["504"]["content"]["application/json"]["schema"] == {"$ref": "#/components/schemas/ErrorBody"}
    assert "413" in schema["paths"]["/api/projects/unarchive"]["post"]["responses"]


def _all_subclasses(root: type) -> set[type]:
    found = set(root.__subclasses__())
    for child in list(found):
        found |= _all_subclasses(child)
    return found


def test_every_error_class_has_a_kind_of_the_table():
    """A new error class without a category (or a kind without a row) would answer nothing sensible."""
    assert servostudio.cli.main  # the CLI's error classes are imported too
    assert set(OUTCOMES) == set(ErrorKind)
    for error_class in _all_subclasses(ServoStudioError):
        if error_class.__name__ == "ProjectError":  # a family; each of its classes names its category first
            continue
        assert error_class.kind in OUTCOMES, error_class
