"""The dashboard's quick test in Chromium against a server in this process (so the test reads the simulator's clock):
the arm switch before any motion, hold-to-run jog (released: the axis stops), homing with the manual's description
of the method, a relative move read back from the drive, and a browser killed in the middle of a held jog stopping
the axis within 200 ms of its last keepalive, measured on the simulator's clock (``tests/support/motion_timing.py``).
"""

from __future__ import annotations

import contextlib
import os
import shutil
import signal
import subprocess
import time
from collections.abc import Callable

import httpx
import pytest
from playwright.sync_api import Browser, Page, expect
from tests.support.browser import CHROMIUM_ARGS
from tests.support.live_server import REPO_ROOT, free_port
from tests.support.motion_timing import DriveProbe, InProcessServer, KeepaliveLog
from tests.support.waits import eventually

BUDGET = 0.2  # seconds from the last keepalive to the stop (issue #13)


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    root = tmp_path_factory.mktemp("jog-ui")
    shutil.copytree(REPO_ROOT / "projects" / "demo", root / "projects" / "demo")
    running = InProcessServer(root)
    yield running
    running.close()


def api(server: InProcessServer, method: str, path: str, **kwargs) -> dict:
    answer = httpx.request(method, f"{server.url}/api/buses/sim/nodes{path}", timeout=15, **kwargs)
    assert answer.is_success, answer.text
    return answer.json()


def state(server: InProcessServer, node: int) -> str:
    return str(api(server, "GET", f"/{node}/state")["state"])


def open_dashboard(page: Page, server: InProcessServer, axis: str) -> None:
    page.goto(f"{server.url}/projects/demo/axes/{axis}")
    page.bring_to_front()
    expect(page.get_by_test_id("motion-test")).to_be_visible()
    expect(page.get_by_test_id("jog-plus")).to_be_disabled()  # nothing moves before the arm switch
    expect(page.get_by_test_id("controller-holder")).to_have_text("Not armed: nobody answers for this axis")
    page.get_by_test_id("motion-arm").click()
    expect(page.get_by_test_id("controller-holder")).to_have_text("Armed by this page")
    expect(page.get_by_test_id("motion-arm")).to_be_checked()
    expect(page.get_by_test_id("jog-plus")).to_be_enabled()


def hold(page: Page, testid: str) -> None:
    page.get_by_test_id(testid).hover()
    page.mouse.down()


def hold_until_enabled(page: Page, server: InProcessServer, testid: str, node: int) -> None:
    """Hold the button until the axis is enabled. A host too loaded to deliver the page's keepalives within the
    hold time while the jog starts has the watchdog end it (the safe side): the user presses again, once."""
    for _attempt in range(2):
        before = _motion_id(server, node)
        hold(page, testid)
        eventually(_enabled_or_watchdog_ended(server, node, before), 10, "the jog")
        if state(server, node) == "OPERATION ENABLED":
            return
        page.mouse.up()
    raise AssertionError("the hold-to-run watchdog ended the jog on both presses")


def _motion_id(server: InProcessServer, node: int) -> object:
    return (api(server, "GET", f"/{node}/motion") or {}).get("id")


def _enabled_or_watchdog_ended(server: InProcessServer, node: int, before: object) -> Callable[[], bool]:
    """The axis enabled, or a motion newer than ``before`` that the hold-to-run watchdog stopped."""

    def ended() -> bool:
        run = api(server, "GET", f"/{node}/motion") or {}
        return run.get("id") != before and run.get("state") == "stopped" and "hold-to-run" in str(run.get("reason"))

    return lambda: state(server, node) == "OPERATION ENABLED" or ended()


def test_a_held_jog_runs_and_stops_when_released(page: Page, server: InProcessServer) -> None:
    open_dashboard(page, server, "X")
    page.get_by_test_id("jog-velocity").fill("90")
    hold_until_enabled(page, server, "jog-plus", 1)
    time.sleep(0.5)  # held: keepalives keep it turning
    assert api(server, "GET", "/1/motion")["state"] == "running"
    assert int(api(server, "GET", "/1/objects/0x606C")["raw"]) > 0
    page.mouse.up()
    expect(page.get_by_test_id("motion-state")).to_contain_text("Jog stopped")
    assert state(server, 1) != "OPERATION ENABLED"
    page.get_by_test_id("motion-arm").click()
    expect(page.get_by_test_id("jog-plus")).to_be_disabled()


def test_homing_shows_the_manuals_description_and_ends_homed(page: Page, server: InProcessServer) -> None:
    open_dashboard(page, server, "Y")
    page.get_by_test_id("homing-method").select_option("35")
    expect(page.get_by_test_id("homing-description")).to_contain_text("current position")
    page.get_by_test_id("homing-method").select_option("-3")
    expect(page.get_by_test_id("homing-description")).to_contain_text("Mechanical limit, negative move")
    page.get_by_test_id("homing-method").select_option("35")
    hold(page, "homing-run")
    expect(page.get_by_test_id("motion-state")).to_contain_text("Homing done")
    page.mouse.up()
    assert api(server, "GET", "/2/motion")["statusword"] & (1 << 12)  # homing attained
    start = int(api(server, "GET", "/2/objects/0x6064")["raw"])
    page.get_by_test_id("move-distance").fill("1024")
    hold(page, "move-run")
    expect(page.get_by_test_id("motion-state")).to_contain_text("Move done")
    page.mouse.up()
    assert abs(int(api(server, "GET", "/2/objects/0x6064")["raw"]) - (start + 1024)) <= 4
    page.get_by_test_id("move-distance").fill("100000")  # above the one-revolution default
    hold(page, "move-run")
    expect(page.get_by_test_id("motion-error")).to_contain_text("distance_revolutions")
    page.mouse.up()
    page.get_by_test_id("motion-arm").click()


def _chromium(tmp_path) -> tuple[subprocess.Popen, int]:
    """A browser of its own (its own process group), to be killed; reached over CDP."""
    port = free_port()
    executable = shutil.which("chromium")
    assert executable, "Debian's chromium is required"
    command = [executable, "--headless=new", f"--remote-debugging-port={port}", f"--user-data-dir={tmp_path}"]
    process = subprocess.Popen(
        [*command, *CHROMIUM_ARGS, "about:blank"], start_new_session=True, stderr=subprocess.DEVNULL
    )
    eventually(lambda: _answers(port), 30, "chromium's DevTools endpoint")
    return process, port


def _answers(port: int) -> bool:
    try:
        return httpx.get(f"http://127.0.0.1:{port}/json/version", timeout=1).is_success
    except httpx.HTTPError:
        return False


def _hold_until_running(page: Page, server: InProcessServer, keepalives: KeepaliveLog, probe: DriveProbe) -> None:
    """Press and hold jog+ until the jog runs on keepalives; under load a late keepalive may stop it early (the safe
    direction, not what this test measures): then release and press again."""
    for _attempt in range(3):
        hold(page, "jog-plus")
        with contextlib.suppress(AssertionError):
            eventually(lambda: len(keepalives.times) > 10 and probe.was_running(), 10, "the held jog")
            if api(server, "GET", "/3/motion")["state"] == "running":
                return
        page.mouse.up()
        time.sleep(0.5)
    raise AssertionError("the held jog did not keep running in 3 tries")


def test_a_browser_killed_mid_jog_stops_the_axis_within_200_ms_of_its_last_keepalive(
    browser: Browser, server: InProcessServer, tmp_path
) -> None:
    process, port = _chromium(tmp_path / "profile")
    try:
        remote = browser.browser_type.connect_over_cdp(f"http://127.0.0.1:{port}")
        page = remote.contexts[0].pages[0] if remote.contexts[0].pages else remote.contexts[0].new_page()
        page.set_viewport_size({"width": 1366, "height": 768})
        open_dashboard(page, server, "Z")
        keepalives = KeepaliveLog(server.network)
        keepalives.install(server)
        probe = DriveProbe(server.network, 3)
        _hold_until_running(page, server, keepalives, probe)
        os.killpg(process.pid, signal.SIGKILL)  # the whole browser, at once
        eventually(lambda: state(server, 3) != "OPERATION ENABLED", 5, "the stop")
        eventually(lambda: probe.samples[-1].time > probe.stop_began() + 0.05, 5, "the samples after the stop")
        probe.stop()
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(process.pid, signal.SIGKILL)
        process.wait(timeout=10)
    last = keepalives.last()
    assert probe.stop_began() - last <= BUDGET, probe.stop_began() - last
    assert probe.standstill() - last <= BUDGET, probe.standstill() - last
    assert api(server, "GET", "/3/motion")["state"] == "stopped"
