"""The scope tab against a simulated XtrapulsPac: configure a capture by name search, trigger it, read a cursor,
export CSV and HTML, save it in the project; the arm / force / stop keys; the redraw time of a 4 × 8192 capture."""

from __future__ import annotations

import re
import time

from playwright.sync_api import Page, expect
from tests.support.browser import DemoServer, open_scope, screenshot


def pick(page: Page, slot: str, query: str, key: str) -> None:
    """Choose an object in a picker by typing part of its name and clicking the result with that address."""
    page.get_by_test_id(slot).fill(query)
    page.get_by_test_id(f"{slot}-results").get_by_test_id("picker-result").filter(has_text=key).first.click()
    expect(page.get_by_test_id(slot)).to_have_value(re.compile(rf"^{re.escape(key)} "))


def test_a_triggered_capture_is_read_at_a_cursor_exported_and_saved(page: Page, demo_server: DemoServer, tmp_path):
    axis, node = demo_server.axes[0]
    demo_server.api("PUT", f"/api/buses/{demo_server.bus}/nodes/{node}/objects/0x60FF,0", json={"value": 0})
    open_scope(page, demo_server, axis)
    pick(page, "scope-ch1", "target velocity", "0x60FF,0")
    pick(page, "scope-ch4", "following error", "0x60F4,0")
    page.get_by_test_id("scope-samples").fill("400")
    pick(page, "scope-trigger", "target velocity", "0x60FF,0")
    page.get_by_test_id("scope-level").fill("100")
    page.get_by_test_id("scope-pretrigger").fill("25")
    page.get_by_test_id("scope-arm").click()
    expect(page.get_by_test_id("scope-stage")).to_have_text("Recorder: waiting")
    demo_server.api("PUT", f"/api/buses/{demo_server.bus}/nodes/{node}/objects/0x60FF,0", json={"value": 500})
    plot = page.get_by_test_id("scope-plot")
    expect(plot).to_have_attribute("data-drawn", re.compile(r"time 4$"))
    expect(page.get_by_test_id("scope-row-1")).to_contain_text("0x60FF,0")

    page.get_by_test_id("scope-cursor-a").fill("-0.00025")
    page.get_by_test_id("scope-cursor-a").press("Enter")
    page.get_by_test_id("scope-cursor-b").fill("0")
    page.get_by_test_id("scope-cursor-b").press("Enter")
    expect(page.get_by_test_id("scope-a-1")).to_have_text("0")  # the sample before the trigger
    expect(page.get_by_test_id("scope-b-1")).to_have_text("500")  # the trigger sample: the step
    expect(page.get_by_test_id("scope-cursor-delta")).to_have_text(re.compile(r"Δt = 0\.25 ms\s+1/Δt = 4000 Hz"))
    plot.click(position={"x": 300, "y": 200})  # a click on the plot moves cursor A
    expect(page.get_by_test_id("scope-cursor-a")).not_to_have_value("-0.00025")
    screenshot(page, "scope-capture")

    with page.expect_download() as csv_download:
        page.get_by_test_id("scope-export-csv").click()
    csv_download.value.save_as(tmp_path / "capture.csv")
    csv_text = (tmp_path / "capture.csv").read_text()
    assert csv_text.startswith("# period: 250 us\n# samples: 400\n# trigger: 0x60FF,0 rising 100 user unit/s\n")
    assert 'time_s,"0x60FF,0","0x606C,0","0x6078,0","0x60F4,0"\n' in csv_text and "\n0,500," in csv_text
    with page.expect_download() as html_download:
        page.get_by_test_id("scope-export-html").click()
    html_download.value.save_as(tmp_path / "capture.html")
    html = (tmp_path / "capture.html").read_text()
    assert "scattergl" in html and "<script src=" not in html

    page.get_by_test_id("scope-save-name").fill("ui step")
    page.get_by_test_id("scope-save").click()
    expect(page.get_by_test_id("scope-saved")).to_contain_text("ui step")
    saved = demo_server.api("GET", f"/api/projects/demo/axes/{axis}/captures/ui step").json()
    assert saved["values"][0][saved["trigger_index"]] == 500 and saved["samples"] == 400


def test_keys_arm_force_and_stop_and_the_fft_view(page: Page, demo_server: DemoServer):
    axis, node = demo_server.axes[1]
    open_scope(page, demo_server, axis)
    page.get_by_test_id("scope-samples").fill("200")
    pick(page, "scope-trigger", "position actual", "0x6064,0")
    page.get_by_test_id("scope-level").fill("1000000000")
    page.locator("body").click(position={"x": 5, "y": 5})  # leave the field: keys act on the page
    page.keyboard.press("a")
    expect(page.get_by_test_id("scope-stage")).to_have_text(re.compile(r"Recorder: (filling|waiting)"))
    page.keyboard.press("f")
    expect(page.get_by_test_id("scope-plot")).to_have_attribute("data-drawn", re.compile(r"time 4$"))
    page.get_by_test_id("scope-view-fft").click()
    expect(page.get_by_test_id("scope-plot")).to_have_attribute("data-drawn", re.compile(r"fft 4$"))
    page.get_by_test_id("scope-mode").select_option("normal")
    page.keyboard.press("a")
    expect(page.get_by_test_id("scope-stage")).to_have_text(re.compile(r"Recorder: (filling|waiting)"))
    page.keyboard.press("s")
    expect(page.get_by_test_id("scope-stage")).to_have_text("Recorder: idle")
    assert demo_server.api("GET", f"/api/buses/{demo_server.bus}/nodes/{node}/scope/status").json()["job"] is None


def test_a_definition_the_drive_cannot_capture_is_refused_with_the_reason(page: Page, demo_server: DemoServer):
    axis, _ = demo_server.axes[2]
    open_scope(page, demo_server, axis)
    page.get_by_test_id("scope-period").fill("300")
    page.get_by_test_id("scope-arm").click()
    expect(page.get_by_test_id("scope-refused")).to_contain_text("multiple of its 250 µs base period")
    expect(page.get_by_test_id("scope-stage")).to_have_text(re.compile(r"Recorder: (idle|done)"))


def test_redraw_of_a_4_by_8192_capture(page: Page, demo_server: DemoServer):
    """Four 8-bit channels fill the 32 KB buffer with 8192 samples each; a cursor move redraws all of them."""
    axis, _ = demo_server.axes[2]
    open_scope(page, demo_server, axis)
    for slot, query, key in (
        ("scope-ch1", "error register", "0x1001,0"),
        ("scope-ch2", "trigger status", "0x5829,0"),
        ("scope-ch3", "modes of operation display", "0x6061,0"),
        ("scope-ch4", "Infranor error code", "0x3023,4"),
    ):
        pick(page, slot, query, key)
    page.get_by_test_id("scope-samples").fill("8192")
    page.get_by_test_id("scope-arm").click()
    plot = page.get_by_test_id("scope-plot")
    page.wait_for_selector("[data-testid=scope-plot][data-drawn], [data-testid=scope-failed]", timeout=100_000)
    expect(page.get_by_test_id("scope-failed")).to_have_count(0)  # else its text says why the capture failed
    expect(plot).to_have_attribute("data-drawn", re.compile(r"time 4$"))
    draws = []
    for when in ("0.1", "0.5", "1"):
        before = plot.get_attribute("data-draw-ms")
        page.get_by_test_id("scope-cursor-a").fill(when)
        page.get_by_test_id("scope-cursor-a").press("Enter")
        expect(plot).not_to_have_attribute("data-draw-ms", before or "")
        draws.append(float(plot.get_attribute("data-draw-ms") or "nan"))
        time.sleep(0.2)
    print(f"redraw of 4 x 8192 samples (software WebGL, headless): {draws} ms")
    assert min(draws) < 1000
