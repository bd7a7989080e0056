"""The shell page, built by Vite and served by the backend, talks to the live server."""

from playwright.sync_api import Page, expect
from tests.support.browser import screenshot

from servostudio import __version__


def test_shell_shows_live_server_version(page: Page, live_server) -> None:
    page.goto(live_server.url + "/")
    status = page.get_by_test_id("server-status")
    expect(status).to_have_text(f"Server online · v{__version__}")
    expect(status).to_have_attribute("data-state", "online")
    expect(page).to_have_title("Servo Studio")
    expect(page.get_by_test_id("user-status")).to_have_text("local · administrator")
    screenshot(page, "shell")


def test_deep_link_falls_back_to_the_shell(page: Page, live_server) -> None:
    page.goto(live_server.url + "/projects/demo/axes/1")
    expect(page.get_by_test_id("server-status")).to_have_attribute("data-state", "online")
