"""A TTA-PRO's dashboard in Chromium against a simulated PROFIBUS-DP slave (docs/profibus.md §12, docs/ui.md): the
live state from its PZD status word and its measurements by the profile's names, no NMT, then the quick test as on
the CANopen drives — armed, a held jog whose motion the position readout shows, a held relative move, and a
homing (PNU 766 0x80: the counter set to the homing offset) seen done — each judged on the simulated slave; and a
fault raised on the drive itself shown live with the manual's text, then reset from the page.

The server runs in this process (``tests/support/ttapro_ui.py``) so the test reads the slave's own counter.
"""

from __future__ import annotations

import re
import time
from collections.abc import Iterator

import pytest
from playwright.sync_api import Page, expect
from tests.support.browser import screenshot
from tests.support.ttapro_ui import NODE, TtaProServer, ttapro_ui_server

from servostudio.sim.drive.statemachine import State
from servostudio.sim.profibus.faults import FOLLOWING_ERROR

POSITION = "readout-0x0306,0"  # PNU 774, the profile's position_actual
HOME_OFFSET = 1000  # PNU 768: where homing 0x80 sets the counter
READOUT = f"Number(document.querySelector(`[data-testid='{POSITION}'] .value`).textContent)"
HERE = "128"  # PNU 766 0x80: home on the current position, counter set to PNU 768


@pytest.fixture(scope="module")
def server(tmp_path_factory) -> Iterator[TtaProServer]:
    # the hold's timing is test_jog_hold.py's: here a loaded host (CI: the held jog expired while the drive enabled)
    # must not end the jog before the page shows it
    with ttapro_ui_server(tmp_path_factory.mktemp("ttapro-ui"), hold_timeout=1.0) as running:
        yield running


def position(page: Page) -> int:
    text = page.get_by_test_id(POSITION).locator(".value").inner_text()
    assert re.fullmatch(r"-?\d+", text), text
    return int(text)


def readout_near(page: Page, value: int, tolerance: int) -> None:
    """Wait until the page's position readout (the live watch of PNU 774) is within ``tolerance`` of ``value``."""
    page.wait_for_function(f"([at, within]) => Math.abs({READOUT} - at) <= within", arg=[value, tolerance])


def hold(page: Page, testid: str) -> None:
    page.get_by_test_id(testid).hover()
    page.mouse.down()


def test_a_ttapro_dashboard_shows_its_state_jogs_moves_and_homes(page: Page, server: TtaProServer) -> None:
    page.goto(f"{server.url}/projects/pb/axes/X")
    page.bring_to_front()
    expect(page.get_by_test_id("dashboard-nmt")).to_have_text("no NMT (PROFIBUS-DP)")
    expect(page.get_by_test_id("dashboard-state")).to_have_text("Switch on disabled")
    expect(page.get_by_test_id("dashboard-statusword")).to_have_text(re.compile(r"0x[0-9A-F]{4}"))
    expect(page.get_by_test_id(POSITION).locator(".value")).to_have_text(re.compile(r"-?\d+"))
    expect(page.get_by_test_id("dashboard-readouts")).to_contain_text("DC bus voltage")
    expect(page.get_by_test_id("dashboard-nmt-commands")).to_have_count(0)
    expect(page.get_by_test_id("qt-run")).to_have_count(0)  # no profile velocity mode on a TTA-PRO
    expect(page.get_by_test_id("homing-method")).to_have_value("0")  # the device's first configuration, not 35
    expect(page.get_by_test_id("homing-description")).to_contain_text("current position")

    page.get_by_test_id("motion-arm").click()
    expect(page.get_by_test_id("controller-holder")).to_have_text("Armed by this page")
    _jog(page, server)
    _move(page, server)
    _home(page, server)
    screenshot(page, "ttapro-dashboard")
    page.get_by_test_id("motion-arm").click()  # released: an enabled axis gets the guard's quick stop
    expect(page.get_by_test_id("jog-plus")).to_be_disabled()
    expect(page.get_by_test_id("dashboard-state")).to_have_text("Switch on disabled")
    assert server.drive_state() is State.SWITCH_ON_DISABLED


def test_a_fault_raised_on_the_drive_shows_live_with_the_manuals_text_and_is_reset(
    page: Page, server: TtaProServer
) -> None:
    page.goto(f"{server.url}/projects/pb/axes/X")
    expect(page.get_by_test_id("dashboard-state")).to_have_text("Switch on disabled")
    expect(page.get_by_test_id("no-faults")).to_be_visible()
    with server.line.line.lock:  # on the drive itself, not through the tool: the page follows its status word
        server.line.slaves[NODE].drive.faults.raise_fault(FOLLOWING_ERROR)
    expect(page.get_by_test_id("dashboard-state")).to_have_text("Fault")
    expect(page.get_by_test_id("dashboard-faults")).to_contain_text("POS: position following error")
    page.get_by_test_id("fault-reset").click()
    expect(page.get_by_test_id("dashboard-state")).to_have_text("Switch on disabled")
    expect(page.get_by_test_id("no-faults")).to_be_visible()


def _jog(page: Page, server: TtaProServer) -> None:
    before = position(page)
    page.get_by_test_id("jog-velocity").fill("120")
    hold(page, "jog-plus")
    expect(page.get_by_test_id("dashboard-state")).to_have_text("Operation enabled")  # the PZD status word, live
    expect(page.get_by_test_id("motion-state")).to_contain_text("Jog running")
    page.wait_for_function(f"start => {READOUT} > start + 200", arg=before)  # the readout follows the held jog
    page.mouse.up()
    expect(page.get_by_test_id("motion-state")).to_contain_text("Jog stopped")
    assert server.counter() > before + 200
    assert server.api("GET", f"/buses/pb/nodes/{NODE}/motion")["state"] == "stopped"


def _move(page: Page, server: TtaProServer) -> None:
    _wait_standstill(server)
    start = server.counter()
    page.get_by_test_id("move-distance").fill("1024")
    hold(page, "move-run")
    expect(page.get_by_test_id("motion-state")).to_contain_text("Move done")
    page.mouse.up()
    assert abs(server.counter() - (start + 1024)) <= 5
    readout_near(page, server.counter(), 5)


def _home(page: Page, server: TtaProServer) -> None:
    server.api("PUT", f"/buses/pb/nodes/{NODE}/objects/home_offset", json={"value": HOME_OFFSET})
    page.get_by_test_id("homing-method").select_option(HERE)
    hold(page, "homing-run")
    expect(page.get_by_test_id("motion-state")).to_contain_text("Homing done")
    page.mouse.up()
    assert abs(server.counter() - HOME_OFFSET) <= 2
    readout_near(page, HOME_OFFSET, 2)


def _wait_standstill(server: TtaProServer) -> None:
    """The jog's quick stop over: the counter no longer moves (the next move starts from rest)."""
    deadline = time.monotonic() + 5
    last = server.counter()
    while time.monotonic() < deadline:
        time.sleep(0.1)
        now = server.counter()
        if now == last:
            return
        last = now
    raise AssertionError("the axis did not come to rest after the jog")
