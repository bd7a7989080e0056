"""Axis dashboard against the simulated drives: enabling needs explicit clicks (arm, then each transition) and the
state follows."""

import re
import time

from playwright.sync_api import Page, expect
from tests.support.browser import DemoServer, screenshot


def drive_state(server: DemoServer, node: int) -> str:
    return server.api("GET", f"/api/buses/{server.bus}/nodes/{node}/state").json()["state"]


def test_live_values_and_enabling_the_axis_step_by_step(page: Page, demo_server: DemoServer) -> None:
    axis, node = demo_server.axes[1]
    page.goto(f"{demo_server.url}/projects/demo/axes/{axis}")
    dc_bus = page.get_by_test_id("readout-0x6079,0").locator(".value")
    expect(dc_bus).to_have_text(re.compile(r"^\d+(\.\d+)?$"))
    assert float(dc_bus.inner_text()) > 0
    expect(page.get_by_test_id("io-outputs").locator(".led")).not_to_have_count(0)
    state = page.get_by_test_id("dashboard-state")
    expect(state).not_to_have_text("—")
    if state.inner_text() != "Switch on disabled":  # leave whatever an earlier run left behind
        page.get_by_test_id("transition-disable_voltage").click()
    expect(state).to_have_text("Switch on disabled")
    assert drive_state(demo_server, node) == "SWITCH ON DISABLED"
    expect(page.get_by_test_id("transition-enable_operation")).to_have_count(0)

    page.get_by_test_id("transition-shutdown").click()
    expect(state).to_have_text("Ready to switch on")
    page.get_by_test_id("transition-switch_on").click()
    expect(state).to_have_text("Switched on")
    expect(page.get_by_test_id("transition-enable_operation")).to_be_disabled()  # motion needs an armed controller
    page.get_by_test_id("control-arm").click()
    expect(page.get_by_test_id("controller-holder")).to_have_text("Armed by this page")
    page.get_by_test_id("transition-enable_operation").click()
    expect(state).to_have_text("Operation enabled")
    assert drive_state(demo_server, node) == "OPERATION ENABLED"
    expect(page.get_by_test_id(f"tree-state-{axis}")).to_have_text("Operation enabled")
    expect(page.locator('[data-testid="dashboard-sw-bits"] .set', has_text="Operation enabled")).to_have_count(1)
    expect(page.get_by_test_id("no-faults")).to_be_visible()

    expect(page.get_by_test_id("qt-acceleration")).not_to_have_value("")
    page.get_by_test_id("qt-velocity").fill("20000")
    page.get_by_test_id("qt-run").click()
    velocity = page.get_by_test_id("readout-0x606C,0").locator(".value")
    expect(velocity).to_have_text(re.compile(r"^(19\d{3}|20\d{3})$"))
    expect(page.get_by_test_id("dashboard-mode")).to_have_text("Profile velocity (3)")
    on_drive = demo_server.api("GET", f"/api/buses/{demo_server.bus}/nodes/{node}/objects/0x606C,0").json()["raw"]
    assert abs(on_drive - 20000) < 1000
    screenshot(page, "dashboard-enabled")
    page.get_by_test_id("qt-stop").click()
    expect(velocity).to_have_text(re.compile(r"^-?\d{1,2}$"))

    page.get_by_test_id("transition-disable_voltage").click()
    expect(state).to_have_text("Switch on disabled")
    assert drive_state(demo_server, node) == "SWITCH ON DISABLED"
    page.get_by_test_id("control-release").click()
    expect(page.get_by_test_id("control-arm")).to_be_visible()


def test_closing_the_page_stops_the_axis_it_enabled(browser, demo_server: DemoServer) -> None:
    """Motion needs a live client: when the page that enabled an axis goes away, the server quick-stops it."""
    axis, node = demo_server.axes[2]
    context = browser.new_context(viewport={"width": 1366, "height": 768})
    page = context.new_page()
    page.goto(f"{demo_server.url}/projects/demo/axes/{axis}")
    state = page.get_by_test_id("dashboard-state")
    expect(state).not_to_have_text("—")
    if state.inner_text() != "Switch on disabled":
        page.get_by_test_id("transition-disable_voltage").click()
    expect(state).to_have_text("Switch on disabled")
    page.get_by_test_id("control-arm").click()
    expect(page.get_by_test_id("controller-holder")).to_have_text("Armed by this page")
    for transition, shown in (
        ("shutdown", "Ready to switch on"),
        ("switch_on", "Switched on"),
        ("enable_operation", "Operation enabled"),
    ):
        page.get_by_test_id(f"transition-{transition}").click()
        expect(state).to_have_text(shown)
    assert drive_state(demo_server, node) == "OPERATION ENABLED"

    context.close()  # the tab goes away: its event socket closes
    deadline = time.monotonic() + 10
    while drive_state(demo_server, node) == "OPERATION ENABLED" and time.monotonic() < deadline:
        time.sleep(0.1)
    assert drive_state(demo_server, node) in ("QUICK STOP ACTIVE", "SWITCH ON DISABLED")
