"""Logging in through the browser UI: the first start's setup page sets the Administrator's password, a user logs
in on the login page and sees its level, and a write its level does not cover is refused (the server's 403 shown
in the page). Against its own `servostudio serve` with users, not the password-less demo server."""

from __future__ import annotations

import re
import time

import pytest
from playwright.sync_api import Page, expect
from tests.support.browser import screenshot
from tests.support.live_server import LiveServer

from servostudio.services.users import Level, UserStore

PASSWORD = "correct horse battery"


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    root = tmp_path_factory.mktemp("ui-access")
    (root / "projects").mkdir()
    live = LiveServer(root / "projects", extra_args=["--bus", "virtual:ui-access"], data_dir=root / "data")
    live.wait_ready()
    yield live
    live.stop()


def setup_link(server: LiveServer) -> str:
    deadline = time.monotonic() + 10
    while not (match := re.search(r"http://\S+/setup\?token=[\w-]+", server.log.read_text())):
        assert time.monotonic() < deadline, server.log.read_text()
        time.sleep(0.05)
    return match.group(0)


def test_the_setup_link_sets_the_administrator_and_logs_in(page: Page, server) -> None:
    page.goto(setup_link(server))
    page.get_by_test_id("setup-password").fill(PASSWORD)
    page.get_by_test_id("setup-password-again").fill(PASSWORD + "typo")
    page.get_by_test_id("setup-submit").click()
    expect(page.get_by_test_id("setup-error")).to_contain_text("differ")
    page.get_by_test_id("setup-password-again").fill(PASSWORD)
    screenshot(page, "setup")
    page.get_by_test_id("setup-submit").click()
    expect(page.get_by_test_id("user-status")).to_contain_text("admin · administrator")
    expect(page).to_have_url(server.url + "/")


def test_an_operator_logs_in_and_is_refused_a_write(page: Page, server) -> None:
    UserStore(server.data_dir).add_user("olga", Level.OPERATOR, PASSWORD)
    page.goto(server.url + "/bus")
    expect(page).to_have_url(re.compile(r"/login\?next=%2Fbus$"))
    expect(page.get_by_test_id("user-status")).to_have_text("not logged in")
    page.get_by_test_id("login-name").fill("olga")
    page.get_by_test_id("login-password").fill("wrong password")
    page.get_by_test_id("login-submit").click()
    expect(page.get_by_test_id("login-error")).to_contain_text("wrong user name or password")
    page.get_by_test_id("login-password").fill(PASSWORD)
    page.get_by_test_id("login-submit").click()
    expect(page).to_have_url(server.url + "/bus")
    expect(page.get_by_test_id("user-status")).to_contain_text("olga · operator")

    page.goto(server.url + "/")
    page.get_by_test_id("new-project").click()
    page.get_by_test_id("new-project-name").fill("not-mine")
    page.get_by_test_id("create-project").click()
    expect(page.get_by_test_id("dialog-error")).to_contain_text("needs the expert level; olga is operator")
    screenshot(page, "refused-at-operator")
    assert not (server.data_dir.parent / "projects" / "not-mine").exists()


def test_logging_out_ends_the_session(page: Page, server) -> None:
    # a user of its own: the setup test's admin may live on another worker's server (pytest-xdist)
    UserStore(server.data_dir).add_user("lena", Level.ADMINISTRATOR, PASSWORD)
    page.goto(server.url + "/login")
    page.get_by_test_id("login-name").fill("lena")
    page.get_by_test_id("login-password").fill(PASSWORD)
    page.get_by_test_id("login-submit").click()
    expect(page.get_by_test_id("user-status")).to_contain_text("lena · administrator")
    page.get_by_test_id("log-out").click()
    expect(page).to_have_url(re.compile(r"/login"))
    page.goto(server.url + "/")
    expect(page).to_have_url(re.compile(r"/login\?next=%2F$"))
