"""The commissioning report from the browser: a project commissioned on the simulator (seed 101's hidden plant,
results saved as the services save them), the "Commissioning report" button of the project page and of the axis
page downloads it; then, with the server stopped and the browser offline, the downloaded file is opened from disk
and its plots render (plotly.js inline), and it prints with each axis on a page of its own."""

from __future__ import annotations

import re
from collections.abc import Iterator

import pytest
from playwright.sync_api import Browser, Page, expect
from tests.support.browser import screenshot
from tests.support.live_server import LiveServer
from tests.support.report_project import commissioned

#: the plots of axis X: the speed and position steps of the auto-tuning's verification, the plant Bode
AXIS_X_PLOTS = ("axis-1-steps-0-speed_step", "axis-1-steps-0-position_step", "axis-1-bode-plant")


@pytest.fixture
def server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[LiveServer]:
    """A server on the commissioned project, on a bus with no drives (the report needs none); the test stops it."""
    root = tmp_path_factory.mktemp("report-download")
    (root / "projects").mkdir()
    commissioned(root / "projects")
    live = LiveServer(root / "projects", ["--bus", "virtual:report-download"])
    try:
        live.wait_ready()
        yield live
    finally:
        live.stop()


def test_the_downloaded_report_opens_offline_with_its_plots(page: Page, browser: Browser, server, tmp_path):
    page.goto(f"{server.url}/projects/demo")
    with page.expect_download() as project_download:
        page.get_by_test_id("report-download").click()
    assert project_download.value.suggested_filename == "demo-report.html"
    project_download.value.save_as(tmp_path / "demo-report.html")

    page.goto(f"{server.url}/projects/demo/axes/X/backup")
    expect(page.get_by_test_id("axis-title")).to_have_text("X")
    with page.expect_download() as axis_download:
        page.get_by_test_id("report-download").click()
    assert axis_download.value.suggested_filename == "demo-X-report.html"
    axis_download.value.save_as(tmp_path / "demo-X-report.html")
    server.stop()

    context = browser.new_context(offline=True, viewport={"width": 1100, "height": 900})
    try:
        offline = context.new_page()
        asked: list[str] = []
        offline.on("request", lambda request: asked.append(request.url))
        offline.goto((tmp_path / "demo-report.html").as_uri())
        for plot in AXIS_X_PLOTS:  # plotly drew each: its SVG with one trace per saved series
            expect(offline.locator(f"#{plot} .main-svg").first).to_be_visible()
            expect(offline.locator(f"#{plot} .scatterlayer .trace")).not_to_have_count(0)
        expect(offline.locator("h2", has_text=re.compile(r"^Axis [XYZ]$"))).to_have_count(3)
        assert [url for url in asked if not url.startswith("file:")] == []  # nothing from the network
        screenshot(offline, "report-offline")
        offline.emulate_media(media="print")
        expect(offline.locator(f"#{AXIS_X_PLOTS[0]} .modebar").first).to_be_hidden()
        assert pdf_pages(offline.pdf()) >= 4  # the project, then each axis starting a page of its own

        offline.goto((tmp_path / "demo-X-report.html").as_uri())
        # one saved plant response: its magnitude, phase and coherence traces
        expect(offline.locator(f"#{AXIS_X_PLOTS[2]} .scatterlayer .trace")).to_have_count(3)
        expect(offline.locator("h2", has_text=re.compile(r"^Axis "))).to_have_text(["Axis X"])
    finally:
        context.close()


def pdf_pages(pdf: bytes) -> int:
    return len(re.findall(rb"/Type\s*/Page(?!s)", pdf))
