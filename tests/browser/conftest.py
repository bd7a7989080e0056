"""Playwright (Python) driving Debian's Chromium against the real server.

Playwright's own browser download is not available here, so the browser is the system's
`chromium`, started with the flags a closed network needs (those, screenshots and the demo server's handle:
`tests/support/browser.py`).
"""

from __future__ import annotations

import os
import shutil

import httpx
import pytest
from playwright.sync_api import Browser, Page, expect, sync_playwright
from tests.support.browser import CHROMIUM_ARGS, DemoServer, screenshot  # noqa: F401 -- screenshot: for test_ttapro_*.py
from tests.support.live_server import REPO_ROOT, LiveServer

# The test machine is shared and slow at times: allow pages more than Playwright's default 5 s to settle.
expect.set_options(timeout=15_000)


# Package scope: Playwright's sync API keeps an event loop running while the browser is open, which would
# break asyncio.run() in the tests collected after this package.
@pytest.fixture(scope="package")
def browser() -> Browser:
    executable = shutil.which("chromium")
    if executable is None:
        pytest.fail("Debian's chromium is required for the browser tests: run `make test`, which installs it")
    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=executable, headless=True, args=CHROMIUM_ARGS)
        yield browser
        browser.close()


@pytest.fixture
def page(browser: Browser) -> Page:
    context = browser.new_context(viewport={"width": 1366, "height": 768}, locale="de-DE")
    page = context.new_page()
    yield page
    context.close()


@pytest.fixture(scope="package")
def demo_server(tmp_path_factory: pytest.TempPathFactory):
    """The UI tests' server: the repository's projects/demo copied into a fresh project store (tests may change it)."""
    root = tmp_path_factory.mktemp("ui")
    projects = root / "projects"
    shutil.copytree(REPO_ROOT / "projects" / "demo", projects / "demo")
    # EDS imports made by the tests go to a scratch library, not the user's (the server reads this at start-up).
    previous = os.environ.get("SERVOSTUDIO_USER_EDS_DIR")
    os.environ["SERVOSTUDIO_USER_EDS_DIR"] = str(root / "user-eds")
    try:
        server = LiveServer(projects)
    finally:
        if previous is None:
            del os.environ["SERVOSTUDIO_USER_EDS_DIR"]
        else:
            os.environ["SERVOSTUDIO_USER_EDS_DIR"] = previous
    try:
        server.wait_ready()
        project = httpx.get(f"{server.url}/api/projects/demo", timeout=15.0).json()
        bus = project["buses"][0]
        # The UI maps a project bus to the server's bus of the same name, else of the same spec; so does the test.
        open_buses = httpx.get(f"{server.url}/api/buses", timeout=15.0).json()
        match = next((b for b in open_buses if b["id"] == bus["name"]), None) or next(
            (b for b in open_buses if b["spec"] == bus["interface"]), None
        )
        if match is None:
            match = httpx.post(
                f"{server.url}/api/buses", json={"spec": bus["interface"], "id": bus["name"]}, timeout=30.0
            ).json()
        axes = tuple((a["name"], a["node_id"]) for a in project["axes"])
        yield DemoServer(server.url, "demo", match["id"], axes, projects)
    finally:
        server.stop()


@pytest.fixture(scope="package")
def live_server(demo_server: DemoServer) -> DemoServer:
    """The browser tests share one server (each runs three simulated drives in real time on a 2-core machine)."""
    return demo_server
