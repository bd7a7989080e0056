"""The project page: "Import DCF…" on an axis row shows what a DCF would change (old → new), and after the user's
confirmation sets the axis's project values to it and lists what it left out (issue 14 a); the kept revisions are
listed with when, who and what, and a chosen one is restored after a confirmation (issue 14 b)."""

from __future__ import annotations

import re

from playwright.sync_api import Page, expect
from tests.support.browser import DemoServer, screenshot
from tests.support.live_server import REPO_ROOT


def _dcf(position_window_time: int) -> bytes:
    """The XtrapulsPac EDS configuring 0x6068 (writable) and the status word 0x6041 (read-only: left out)."""
    text = (REPO_ROOT / "eds" / "xtrapulspac.eds").read_text(encoding="latin-1")
    text = text.replace("[6068]\n", f"[6068]\nParameterValue={position_window_time}\n", 1)
    return text.replace("[6041]\n", "[6041]\nParameterValue=7\n", 1).encode("latin-1")


def test_import_a_dcf_then_restore_the_revision_it_replaced(page: Page, demo_server: DemoServer) -> None:
    axis, _node = demo_server.axes[2]
    parameter = f"/api/projects/demo/axes/{axis}/parameters/0x6068"
    old = demo_server.api("GET", parameter).json()["value"]
    before = demo_server.api("GET", "/api/projects/demo").json()["revision"]
    page.goto(f"{demo_server.url}/projects/demo")
    with page.expect_file_chooser() as chooser:
        page.get_by_test_id(f"import-dcf-{axis}").click()
    chooser.value.set_files(files=[{"name": "line.dcf", "mimeType": "text/plain", "buffer": _dcf(old + 7)}])

    # first the server checks it all and the user confirms the list of changes; nothing is written before
    expect(page.get_by_test_id("confirm-text")).to_have_text(
        f"1 project value of axis {axis} change to what line.dcf configures (project → DCF)."
    )
    line = page.locator('[data-testid="confirm-change"][data-address="0x6068,0"]')
    expect(line).to_contain_text(f"{old} ms")
    expect(line).to_contain_text(f"{old + 7} ms")
    expect(page.get_by_test_id("confirm-note").first).to_contain_text("1 configured value the project cannot hold")
    assert demo_server.api("GET", "/api/projects/demo").json()["revision"] == before
    page.get_by_test_id("confirm").click()

    result = page.get_by_test_id("dcf-result")
    expect(result).to_contain_text(f"Axis {axis}: 1 project value set from line.dcf. 1 configured value left out:")
    expect(page.get_by_test_id("dcf-skipped").locator("li")).to_have_count(1)
    expect(page.get_by_test_id("dcf-skipped")).to_contain_text("0x6041")
    assert demo_server.api("GET", parameter).json()["value"] == old + 7

    newest = page.get_by_test_id("revision-row").first  # the list followed the project's new revision
    expect(newest).to_have_attribute("data-revision", before)
    expect(newest).to_contain_text(f"import of line.dcf into axis {axis}")
    expect(newest.locator("td").nth(1)).to_have_text(re.compile(r"\S"))  # who
    screenshot(page, "project-dcf-import-revisions")

    newest.get_by_test_id("revision-restore").click()  # a revision may be kept twice: the row is the choice
    expect(page.get_by_role("dialog", name="Restore project revision")).to_contain_text(
        f'what it was at revision {before}, before "import of line.dcf into axis {axis}"'
    )
    page.get_by_test_id("confirm").click()
    expect(page.get_by_test_id("revisions-message")).to_have_text(f"Project demo restored to revision {before}.")
    assert demo_server.api("GET", "/api/projects/demo").json()["revision"] == before
    assert demo_server.api("GET", parameter).json()["value"] == old
    expect(page.get_by_test_id("revision-row").first).to_contain_text(f"restore of revision {before}")


def test_a_refused_dcf_says_why_and_names_the_file(page: Page, demo_server: DemoServer) -> None:
    axis, _node = demo_server.axes[2]
    page.goto(f"{demo_server.url}/projects/demo")
    with page.expect_file_chooser() as chooser:
        page.get_by_test_id(f"import-dcf-{axis}").click()
    chooser.value.set_files(files=[{"name": "bad.dcf", "mimeType": "text/plain", "buffer": _dcf(40000)}])
    message = page.get_by_test_id("page-message")
    expect(message).to_contain_text(re.compile(r"^bad\.dcf:\d+: \[6068\] ParameterValue 40000 is outside"))
    expect(page.get_by_test_id("dcf-result")).to_have_count(0)
    expect(page.get_by_test_id("confirm")).to_have_count(0)  # refused by the check: nothing to confirm
