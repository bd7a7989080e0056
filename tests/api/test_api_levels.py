"""Who may do what, route by route: every REST route and WebSocket declares a level, and every route is called with
every level over HTTP. A caller below the declared level gets 403 ``forbidden`` with the taxonomy's body, one
without credentials 401 ``unauthenticated``; a caller at or above it gets past the check (whatever the route then
answers for dummy arguments). ``docs/security.md``'s route table is the app's own, checked here."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from fastapi.routing import APIRoute, APIWebSocketRoute, RouteContext, iter_route_contexts
from fastapi.testclient import TestClient
from starlette.testclient import WebSocketDenialResponse
from tests.support.access import admin_app, bearer, token

from servostudio.api.routes.events import EVENT_MESSAGES, TERMINAL_MESSAGES
from servostudio.api.routes.scope import ROLL_MESSAGES
from servostudio.api.security import declared_levels
from servostudio.services.settings import Settings
from servostudio.services.users import Level

REPO = Path(__file__).resolve().parents[2]
SECURITY_DOC = REPO / "docs" / "security.md"
#: the framework's own pages (schema and interactive docs) and the UI's static files: public by nature
FRAMEWORK_PATHS = {"/openapi.json", "/docs", "/docs/oauth2-redirect", "/redoc", "/assets"}
#: path parameters (any other NAME is "noNAME"): nothing that exists, so a call past the level check changes nothing
DUMMIES = {
    "bus": "nobus",
    "node": "1",
    "key": "0x6040",
    "name": "nosuch",
    "axis": "noaxis",
    "address": "0x6040",
    "job_id": "job-none",
    "device": "nodevice",
    "reference": "nomotor",
    "token_id": "notoken",
    "capture_id": "nocapture",
}
BODY_METHODS = {"POST", "PUT", "PATCH"}


@pytest.fixture(scope="module")
def app(tmp_path_factory):
    root = tmp_path_factory.mktemp("levels")
    static = root / "static"
    static.mkdir()
    (static / "index.html").write_text("<title>Servo Studio</title>")
    (static / "assets").mkdir()
    return admin_app(Settings(projects_dir=root / "projects", static_dir=static), root / "data")


@pytest.fixture(scope="module")
def client(app):
    with TestClient(app) as client:
        yield client


@pytest.fixture(scope="module")
def tokens(app) -> dict[Level, str]:
    return {level: token(app.state.server.settings.data_dir, level) for level in Level}


def routes(app) -> list[RouteContext]:
    """Every route as the app serves it (FastAPI keeps included routers lazy: ``app.routes`` is not flat)."""
    return list(iter_route_contexts(app.routes))


def api_routes(app) -> list[RouteContext]:
    return [route for route in routes(app) if isinstance(route.original_route, APIRoute | APIWebSocketRoute)]


def calls(app) -> list[tuple[str, str, Level | None]]:
    """(method, path, declared level) of every REST route; the path with dummy arguments."""
    found = []
    for route in api_routes(app):
        if isinstance(route.original_route, APIRoute):
            found += [(method, route.path, declared_levels(route)[0]) for method in sorted(route.methods)]
    return found


def concrete(path: str) -> str:
    return re.sub(r"\{(\w+)(:\w+)?\}", lambda match: DUMMIES.get(match.group(1), f"no{match.group(1)}"), path)


def call(client: TestClient, method: str, path: str, headers: dict[str, str]):
    body = {"json": {}} if method in BODY_METHODS else {}
    return client.request(method, concrete(path), headers=headers, **body)


def test_every_route_declares_exactly_one_level(app):
    undeclared = [route.path for route in api_routes(app) if len(declared_levels(route)) != 1]
    assert not undeclared, f"routes without exactly one declared level (add dependencies=[Requires(…)]): {undeclared}"


def test_nothing_else_is_routed_without_a_declaration(app):
    others = {route.path for route in routes(app)} - {route.path for route in api_routes(app)}
    assert others <= FRAMEWORK_PATHS, others - FRAMEWORK_PATHS
    assert len(api_routes(app)) > 60  # the flattening found the included routers' routes


def test_every_api_path_is_under_api(app):
    assert all(route.path.startswith("/api/") for route in api_routes(app))


def test_a_caller_below_the_level_is_refused_and_one_at_it_gets_past(app, client, tokens):
    problems = []
    for method, path, declared in calls(app):
        for level, text in tokens.items():
            answer = call(client, method, path, bearer(text))
            refused = answer.status_code == 403 and answer.json().get("error") == "LevelTooLow"
            if declared is not None and not level.at_least(declared):
                body = answer.json()
                if not refused or body["kind"] != "forbidden" or f"needs the {declared} level" not in body["detail"]:
                    problems.append(f"{level} {method} {path}: expected 403 forbidden, got {answer.status_code}")
            elif answer.status_code in (401, 403):
                problems.append(f"{level} {method} {path}: refused at a level it declares ({answer.text})")
    assert not problems, "\n".join(problems)


def test_without_credentials_only_the_public_routes_answer(app, client):
    problems = []
    for method, path, declared in calls(app):
        answer = call(client, method, path, {})
        if declared is None and answer.status_code in (401, 403):
            problems.append(f"{method} {path} is public but answered {answer.status_code}")
        if declared is not None and (answer.status_code, answer.json().get("kind")) != (401, "unauthenticated"):
            problems.append(f"{method} {path}: expected 401 unauthenticated, got {answer.status_code}")
    assert not problems, "\n".join(problems)


@pytest.mark.parametrize(
    ("path", "url"),
    [("/api/ws/events",) * 2, ("/api/ws/terminal",) * 2, ("/api/ws/scope/{roll}", "/api/ws/scope/no-roll")],
)
def test_websockets_need_a_caller_of_their_level(app, client, tokens, path, url):
    route = next(route for route in api_routes(app) if route.path == path)
    assert declared_levels(route) == [Level.OPERATOR]
    with pytest.raises(WebSocketDenialResponse) as denied, client.websocket_connect(url):
        pass
    assert denied.value.status_code == 401 and denied.value.json()["kind"] == "unauthenticated"
    for text in tokens.values():
        with client.websocket_connect(url, headers=bearer(text)):
            pass


TERMINAL_REQUESTS = {  # each answers once (the watch last: it goes on answering)
    "read": {"op": "read", "items": []},
    "write": {"op": "write", "bus": "nobus", "node": 1, "object": "0x6040", "value": 0},
    "watch": {"op": "watch", "items": [{"bus": "nobus", "node": 1, "object": "0x6041"}], "period_ms": 1000},
}


def test_every_terminal_message_has_a_level_and_is_checked_per_level(client, tokens):
    assert set(TERMINAL_MESSAGES) == set(TERMINAL_REQUESTS)
    # the event socket's one client message, the hold-to-run keepalive (tests/api/test_motion_quick_test.py checks it)
    assert EVENT_MESSAGES == {"keepalive": Level.MAINTENANCE}
    # the roll socket's one client message, its stop (every level that may roll may stop it: Operator)
    assert ROLL_MESSAGES == {"stop": Level.OPERATOR}
    for level, text in tokens.items():
        with client.websocket_connect("/api/ws/terminal", headers=bearer(text)) as socket:
            for operation, request in TERMINAL_REQUESTS.items():
                socket.send_json(request)
                answer = socket.receive_json()
                forbidden = answer.get("kind") == "forbidden"
                assert forbidden == (not level.at_least(TERMINAL_MESSAGES[operation])), (level, operation, answer)


def route_table(app) -> str:
    """docs/security.md's table of routes and levels, as the app declares them."""
    rows = [(path, method, declared) for method, path, declared in calls(app)]
    sockets = [route for route in api_routes(app) if isinstance(route.original_route, APIWebSocketRoute)]
    rows += [(route.path, "WS", declared_levels(route)[0]) for route in sockets]
    rows = [row for row in rows if row[1] != "HEAD"]
    lines = ["| method | path | level |", "|---|---|---|"]
    lines += [f"| {method} | `{path}` | {declared or 'anyone'} |" for path, method, declared in sorted(set(rows))]
    return "\n".join(lines)


TABLE = re.compile(r"(<!-- route table: generated -->\n)(.*?)(\n<!-- end of route table -->)", re.S)


def test_the_security_doc_lists_every_route_with_its_level(app):
    documented = TABLE.search(SECURITY_DOC.read_text(encoding="utf-8"))
    assert documented, "docs/security.md lost its route table markers"
    assert documented.group(2) == route_table(app), (
        "docs/security.md's route table differs from the app's: run `.venv/bin/python -m tests.api.test_api_levels`"
    )


def _rewrite_the_security_doc() -> None:
    """``python -m tests.api.test_api_levels``: write the app's route table into docs/security.md."""
    import tempfile

    with tempfile.TemporaryDirectory() as folder:
        table = route_table(admin_app(Settings(static_dir=Path(folder)), Path(folder)))
    text = SECURITY_DOC.read_text(encoding="utf-8")
    SECURITY_DOC.write_text(TABLE.sub(lambda match: match.group(1) + table + match.group(3), text), encoding="utf-8")


if __name__ == "__main__":
    _rewrite_the_security_doc()
