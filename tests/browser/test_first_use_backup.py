"""Issue 14, backup and compare: "Back up drive into project" asks with a summary of what changes (the list on
demand), reports success as success with a complete note of what it left out, and keeps the previous project
revision restorable; compare counts only what a user can write or restore, read-only entries apart."""

import re

from playwright.sync_api import Page, expect
from tests.support.browser import DemoServer, screenshot

STATUSWORD_KEY = f"{0x6041}.0"


def test_backup_into_the_project_asks_reports_and_can_be_undone(page: Page, demo_server: DemoServer) -> None:
    axis, node = demo_server.axes[1]
    on_drive = demo_server.api("GET", f"/api/buses/{demo_server.bus}/nodes/{node}/objects/0x6068,0").json()["raw"]
    set_before = demo_server.api(
        "PUT", f"/api/projects/demo/axes/{axis}/parameters", json={"values": {"0x6068": on_drive + 3}}
    ).json()
    before = set_before["revision"]
    page.goto(f"{demo_server.url}/projects/demo/axes/{axis}/backup")
    page.get_by_test_id("backup-to-project").click()
    text = page.get_by_test_id("confirm-text")
    expect(text).to_contain_text(re.compile(r"project values change \(project → drive\)"))
    changed = int(re.search(r"(\d+) project values change", text.inner_text()).group(1))
    assert changed > 1
    details = page.get_by_test_id("confirm-details")
    expect(details).to_contain_text(f"Show the {changed} changes")
    details.locator("summary").click()
    line = page.locator('[data-testid="confirm-change"][data-address="0x6068,0"]')
    expect(line).to_contain_text(f"{on_drive + 3} ms")
    expect(line).to_contain_text(f"{on_drive} ms")
    expect(page.get_by_test_id("confirm-note").first).to_contain_text("kept as a revision")
    screenshot(page, "first-use-backup-confirm")
    page.get_by_test_id("confirm").click()

    result = page.get_by_test_id("backup-result").locator(".message")
    expect(result).to_contain_text(f"of node {node} stored in project demo: {changed} changed.")
    expect(result).to_have_class(re.compile(r"\bok\b"))  # nothing failed: a success, not a warning
    left = re.search(r"(\d+) drive values the project cannot hold were left out", result.inner_text())
    notes = page.get_by_test_id("backup-notes").locator("li")
    if left:  # the note is complete: every entry left out is listed, with its reason
        expect(notes).to_have_count(int(left.group(1)))
        expect(notes.first).to_contain_text("left out: 0x")
    assert demo_server.api("GET", f"/api/projects/demo/axes/{axis}/parameters/0x6068").json()["value"] == on_drive
    expect(page.get_by_test_id("kept-revision")).to_contain_text(f"revision {before}")
    screenshot(page, "first-use-backup-done")

    page.get_by_test_id("restore-revision").click()
    page.get_by_test_id("confirm").click()
    expect(result).to_have_text(f"Project demo restored to revision {before}.")
    assert demo_server.api("GET", "/api/projects/demo").json()["revision"] == before
    assert demo_server.api("GET", f"/api/projects/demo/axes/{axis}/parameters/0x6068").json()["value"] == on_drive + 3


def test_compare_counts_what_can_be_written_and_offers_read_only_entries_apart(
    page: Page, demo_server: DemoServer
) -> None:
    axis, _node = demo_server.axes[0]
    rows = demo_server.api("GET", f"/api/projects/demo/axes/{axis}/parameters?include_unsaved=true").json()
    writable = sum(1 for row in rows["parameters"] if row["editable"])
    page.goto(f"{demo_server.url}/projects/demo/compare")
    for other, _ in demo_server.axes[1:]:
        page.get_by_test_id(f"compare-axis-{other}").uncheck()
    page.get_by_test_id("compare-drive").check()
    summary = page.get_by_test_id("compare-summary")
    expect(summary).to_contain_text(f"of {writable} writable entries differ")
    table = page.get_by_test_id("compare-table")
    expect(table).to_be_visible()
    page.get_by_test_id("compare-only-diff").uncheck()
    expect(table.locator(f'tr[data-key="{STATUSWORD_KEY}"]')).to_have_count(0)  # the status word is not compared
    page.get_by_test_id("compare-read-only").check()
    apart = page.get_by_test_id("compare-read-only-table")
    statusword = apart.locator(f'tr[data-key="{STATUSWORD_KEY}"]')
    expect(statusword).to_have_count(1)
    expect(statusword).to_contain_text(re.compile(r"\d"))
    expect(summary).to_contain_text(re.compile(r"\d+ read-only entries apart, not counted"))
    expect(summary).to_contain_text(f"of {writable} writable entries differ")
    screenshot(page, "first-use-compare-read-only")
