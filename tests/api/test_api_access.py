"""Access over real HTTP, against `servostudio serve` processes: the first start's one-time setup link, browser
sessions with their CSRF token, API tokens (level, expiry, revocation), login rate limits, the Host and Origin
checks (DNS rebinding, foreign pages, WebSocket upgrades), the password-less opt-in, and what is stored."""

from __future__ import annotations

import contextlib
import re
import stat
import time
from collections.abc import Iterator
from pathlib import Path

import httpx
import pytest
from fastapi.testclient import TestClient
from tests.support.access import admin_app, bearer
from tests.support.live_server import LiveServer

from servostudio.services.settings import Settings
from servostudio.services.users import Level, UserStore

PASSWORD = "correct horse battery"
NO_DRIVES = ["--bus", "virtual:access-tests"]  # a bus with nothing on it: these tests move nothing
WEBSOCKET_UPGRADE = {
    "Connection": "Upgrade",
    "Upgrade": "websocket",
    "Sec-WebSocket-Version": "13",
    "Sec-WebSocket-Key": "dGhlIHNhbXBsZSBub25jZQ==",
}


def start(root: Path, data_dir: Path) -> LiveServer:
    projects = root / "projects"
    projects.mkdir(exist_ok=True)
    server = LiveServer(projects, extra_args=NO_DRIVES, data_dir=data_dir)
    server.wait_ready()
    return server


@pytest.fixture(scope="module")
def fresh(tmp_path_factory):
    """A first start: an empty data directory."""
    root = tmp_path_factory.mktemp("access")
    server = start(root, root / "data")
    yield server
    server.stop()


def setup_token(server: LiveServer) -> str:
    deadline = time.monotonic() + 10
    while not (match := re.search(r"/setup\?token=([\w-]+)", server.log.read_text())):
        assert time.monotonic() < deadline, server.log.read_text()
        time.sleep(0.05)
    return match.group(1)


def refused(answer: httpx.Response, status: int, kind: str, error: str) -> str:
    body = answer.json()
    assert (answer.status_code, body["kind"], body["error"]) == (status, kind, error), body
    return body["detail"]


def test_first_start_sets_the_administrator_through_a_one_time_link(fresh):
    token = setup_token(fresh)
    assert f"http://127.0.0.1:{fresh.port}/setup?token=" in fresh.log.read_text()
    assert httpx.get(f"{fresh.url}/api/setup").json() == {"needed": True, "passwordless": False}
    refused(httpx.get(f"{fresh.url}/api/buses"), 401, "unauthenticated", "NotLoggedIn")
    wrong = httpx.post(f"{fresh.url}/api/setup", json={"token": "guess", "name": "admin", "password": PASSWORD})
    refused(wrong, 403, "forbidden", "SetupRefused")
    weak = httpx.post(f"{fresh.url}/api/setup", json={"token": token, "name": "admin", "password": "admin"})
    assert "at least 10 characters" in refused(weak, 422, "invalid_input", "WeakPassword")  # the token survives

    done = httpx.post(f"{fresh.url}/api/setup", json={"token": token, "name": "admin", "password": PASSWORD})
    assert done.json() == {"name": "admin", "level": "administrator"}
    session = next(value for name, value in done.headers.multi_items() if "servostudio_session=" in value)
    assert "HttpOnly" in session and "SameSite=strict" in session and "Secure" not in session  # plain HTTP
    again = httpx.post(f"{fresh.url}/api/setup", json={"token": token, "name": "eve", "password": PASSWORD})
    refused(again, 403, "forbidden", "SetupRefused")
    assert httpx.get(f"{fresh.url}/api/setup").json()["needed"] is False


def test_the_store_is_private_and_holds_no_secret(fresh):
    store = fresh.data_dir / "users.json"
    assert stat.S_IMODE(store.stat().st_mode) == 0o600
    assert stat.S_IMODE(fresh.data_dir.stat().st_mode) == 0o700
    text = store.read_text()
    assert PASSWORD not in text and "$argon2id$" in text


@contextlib.contextmanager
def log_in(server: LiveServer, name: str = "admin", password: str = PASSWORD) -> Iterator[httpx.Client]:
    """A browser: the cookies of a login."""
    with httpx.Client(base_url=server.url, timeout=10) as client:
        answer = client.post("/api/session", json={"name": name, "password": password})
        assert answer.status_code == 200, answer.text
        yield client


def test_a_browser_session_changes_things_only_with_its_csrf_token(fresh):
    with log_in(fresh) as browser:
        assert browser.get("/api/me").json() == {"name": "admin", "level": "administrator"}
        forged = browser.post("/api/projects", json={"name": "forged"})
        assert "X-CSRF-Token" in refused(forged, 403, "forbidden", "CsrfRefused")
        csrf = {"X-CSRF-Token": browser.cookies["servostudio_csrf"]}
        assert browser.post("/api/projects", json={"name": "mine"}, headers=csrf).status_code == 201
        assert browser.delete("/api/session").status_code == 204
        refused(browser.get("/api/me"), 401, "unauthenticated", "NotLoggedIn")


def test_tokens_carry_a_level_need_no_csrf_and_end_when_revoked_or_expired(fresh):
    with log_in(fresh) as browser:
        csrf = {"X-CSRF-Token": browser.cookies["servostudio_csrf"]}
        made = browser.post("/api/tokens", json={"level": "operator", "days": 1, "label": "hmi"}, headers=csrf).json()
    assert made["level"] == "operator" and made["owner"] == "admin" and made["token"].startswith("sst_")
    assert made["token"] not in (fresh.data_dir / "users.json").read_text()
    script = bearer(made["token"])
    assert httpx.get(f"{fresh.url}/api/me", headers=script).json() == {"name": "admin", "level": "operator"}
    refusal = httpx.post(f"{fresh.url}/api/projects", json={"name": "p"}, headers=script)
    assert "needs the expert level" in refused(refusal, 403, "forbidden", "LevelTooLow")
    above = httpx.post(f"{fresh.url}/api/tokens", json={"level": "expert"}, headers=script)
    refused(above, 403, "forbidden", "LevelTooLow")  # never more than the caller's own level

    assert httpx.delete(f"{fresh.url}/api/tokens/{made['id']}", headers=script).status_code == 204
    refused(httpx.get(f"{fresh.url}/api/me", headers=script), 401, "unauthenticated", "InvalidToken")
    past = UserStore(fresh.data_dir, clock=lambda: time.time() - 2 * 86_400)
    expired, _ = past.create_token(Level.ADMINISTRATOR, days=1)
    assert "expired" in refused(
        httpx.get(f"{fresh.url}/api/me", headers=bearer(expired)), 401, "unauthenticated", "InvalidToken"
    )
    refused(httpx.get(f"{fresh.url}/api/me", headers=bearer("sst_nope_nope")), 401, "unauthenticated", "InvalidToken")


def test_a_new_level_or_a_removed_user_applies_to_open_sessions(fresh):
    admin = bearer(UserStore(fresh.data_dir).create_token(Level.ADMINISTRATOR, days=1)[0])
    body = {"name": "carol", "level": "expert", "password": PASSWORD}
    assert httpx.post(f"{fresh.url}/api/users", json=body, headers=admin).status_code == 201
    with log_in(fresh, "carol") as carol:
        assert carol.get("/api/me").json()["level"] == "expert"
        httpx.patch(f"{fresh.url}/api/users/carol", json={"level": "operator"}, headers=admin).raise_for_status()
        assert carol.get("/api/me").json()["level"] == "operator"
        assert httpx.delete(f"{fresh.url}/api/users/carol", headers=admin).status_code == 204
        refused(carol.get("/api/me"), 401, "unauthenticated", "NotLoggedIn")
    last = httpx.delete(f"{fresh.url}/api/users/admin", headers=admin)
    refused(last, 409, "conflict", "LastAdministrator")


def test_foreign_host_names_and_pages_are_refused(fresh):
    admin = bearer(UserStore(fresh.data_dir).create_token(Level.ADMINISTRATOR, days=1)[0])
    rebound = httpx.get(f"{fresh.url}/api/health", headers={"Host": f"attacker.example:{fresh.port}"})
    assert "not this server's name" in refused(rebound, 403, "forbidden", "HostRefused")
    assert httpx.get(f"{fresh.url}/api/health", headers={"Host": f"localhost:{fresh.port}"}).status_code == 200
    foreign = {**admin, "Origin": "https://attacker.example"}
    refused(httpx.post(f"{fresh.url}/api/buses/nobus/scan", headers=foreign), 403, "forbidden", "OriginRefused")
    refused(
        httpx.get(f"{fresh.url}/api/ws/terminal", headers={**foreign, **WEBSOCKET_UPGRADE}),
        403,
        "forbidden",
        "OriginRefused",
    )
    own = {**admin, "Origin": fresh.url}
    assert httpx.get(f"{fresh.url}/api/buses", headers=own).status_code == 200
    upgraded = httpx.get(f"{fresh.url}/api/ws/events", headers={**own, **WEBSOCKET_UPGRADE})
    assert upgraded.status_code == 101


def test_unknown_api_paths_are_json_404s(fresh):
    for method in ("GET", "POST", "DELETE"):
        answer = httpx.request(method, f"{fresh.url}/api/no/such/route")
        refused(answer, 404, "not_found", "UnknownRoute")
    assert httpx.delete(f"{fresh.url}/api/health").status_code == 405  # a known path keeps its methods


def test_login_is_rate_limited_per_user_and_per_address(tmp_path):
    store = UserStore(tmp_path / "data")
    store.add_user("dave", Level.MAINTENANCE, PASSWORD)
    server = start(tmp_path, tmp_path / "data")
    try:
        login = f"{server.url}/api/session"
        for _ in range(5):
            refused(
                httpx.post(login, json={"name": "dave", "password": "wrong!"}), 401, "unauthenticated", "WrongPassword"
            )
        locked = httpx.post(login, json={"name": "dave", "password": PASSWORD})  # even the right password
        assert "try again in" in refused(locked, 429, "rate_limited", "TooManyLogins")
        assert 14 * 60 < int(locked.headers["Retry-After"]) <= 15 * 60  # the window is 15 minutes
        for attempt in range(15):  # 5 + 15 = 20 failures from this address, each name tried once
            refused(
                httpx.post(login, json={"name": f"nobody{attempt}", "password": "x"}),
                401,
                "unauthenticated",
                "WrongPassword",
            )
        refused(httpx.post(login, json={"name": "someone", "password": "x"}), 429, "rate_limited", "TooManyLogins")
    finally:
        server.stop()


def test_password_less_mode_is_an_explicit_choice_for_this_machine_only(tmp_path):
    server = start(tmp_path, tmp_path / "data")
    try:
        token = setup_token(server)
        refused(httpx.get(f"{server.url}/api/buses"), 401, "unauthenticated", "NotLoggedIn")
        chosen = httpx.post(f"{server.url}/api/setup", json={"token": token, "passwordless": True})
        assert chosen.status_code == 200 and chosen.json() is None
        assert httpx.get(f"{server.url}/api/me").json() == {"name": "local", "level": "administrator"}
        foreign = httpx.post(f"{server.url}/api/buses/nobus/scan", headers={"Origin": "https://attacker.example"})
        refused(foreign, 403, "forbidden", "OriginRefused")  # no password, but still no foreign page
    finally:
        server.stop()


def in_process(tmp_path: Path, **settings) -> TestClient:
    app = admin_app(Settings(projects_dir=tmp_path / "projects", static_dir=tmp_path / "no-ui", **settings), tmp_path)
    return TestClient(app, base_url="https://testserver")  # as behind a TLS-terminating proxy


def test_cookies_are_secure_over_tls(tmp_path):
    UserStore(tmp_path).add_user("admin", Level.ADMINISTRATOR, PASSWORD)
    answer = in_process(tmp_path).post("/api/session", json={"name": "admin", "password": PASSWORD})
    cookies = [value for name, value in answer.headers.multi_items() if name == "set-cookie"]
    assert len(cookies) == 2 and all("Secure" in cookie and "SameSite=strict" in cookie for cookie in cookies)


def test_password_less_mode_serves_loopback_callers_only(tmp_path):
    UserStore(tmp_path).choose_passwordless()
    client = in_process(tmp_path)  # the test client's address is "testclient", not loopback
    refused(client.get("/api/me"), 401, "unauthenticated", "NotLoggedIn")


def test_password_less_mode_cannot_be_chosen_for_a_server_of_the_network(tmp_path):
    client = in_process(tmp_path, host="0.0.0.0")
    token = client.app.state.server.access.setup.token()  # what the console shows
    chosen = client.post("/api/setup", json={"token": token, "passwordless": True})
    assert "needs a loopback address" in refused(chosen, 409, "conflict", "PasswordlessRefused")
    assert not UserStore(tmp_path).contents().passwordless


def test_changing_ones_password_asks_the_current_one_again(tmp_path):
    UserStore(tmp_path).add_user("erin", Level.OPERATOR, PASSWORD)
    browser = in_process(tmp_path)
    assert browser.post("/api/session", json={"name": "erin", "password": PASSWORD}).status_code == 200
    csrf = {"X-CSRF-Token": browser.cookies["servostudio_csrf"]}
    wrong = browser.put("/api/me/password", json={"current": "guess", "new": "another long one"}, headers=csrf)
    refused(wrong, 401, "unauthenticated", "WrongPassword")
    changed = browser.put("/api/me/password", json={"current": PASSWORD, "new": "another long one"}, headers=csrf)
    assert changed.status_code == 204 and UserStore(tmp_path).authenticate("erin", "another long one")
