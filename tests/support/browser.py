"""What the browser tests share: Debian's Chromium's flags for a closed network, full-page screenshots as test
artifacts, the handle of the demo project's server, the XtrapulsPac's entry count the editor lists, and opening
an axis's scope page."""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import httpx
from playwright.sync_api import Page, expect

ARTIFACTS = Path(__file__).resolve().parents[2] / "test-artifacts" / "screenshots"
CHROMIUM_ARGS = [
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]


def screenshot(page: Page, name: str) -> Path:
    """Save a full-page screenshot as a test artifact (test-artifacts/screenshots/NAME.png)."""
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    path = ARTIFACTS / f"{name}.png"
    page.screenshot(path=str(path), full_page=True)
    return path


@dataclass(frozen=True)
class DemoServer:
    """A real `servostudio serve` whose project store holds a copy of the shipped demo project, with its bus open."""

    url: str
    project: str
    bus: str
    axes: tuple[tuple[str, int], ...]  # (axis name, node ID)
    projects_dir: Path | None = None  # the server's project store (tests may save records there, as the server would)

    def api(self, method: str, path: str, **kwargs) -> httpx.Response:
        response = httpx.request(method, self.url + path, timeout=15.0, **kwargs)
        assert response.is_success, f"{method} {path}: HTTP {response.status_code} {response.text}"
        return response


def xtrapulspac_entries() -> int:
    """How many entries the editor lists for the XtrapulsPac: every sub-entry of its dictionary, from the EDS."""
    from servostudio.od import BUILTIN_EDS_DIR, EdsLibrary

    return len(EdsLibrary(BUILTIN_EDS_DIR).load("xtrapulspac"))


def open_scope(page: Page, server: DemoServer, axis: str) -> None:
    """The scope page of ``axis`` in the demo project, once its recorder state is shown."""
    page.goto(f"{server.url}/projects/demo/axes/{axis}/scope")
    expect(page.get_by_test_id("scope-stage")).to_have_text(re.compile(r"Recorder: (idle|done)"))
