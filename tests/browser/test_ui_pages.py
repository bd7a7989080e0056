"""Projects, bus scan, dialog terminal, backup into the project, compare: clicked through against the real server."""

import re

from playwright.sync_api import Page, expect
from tests.support.browser import DemoServer, screenshot


def test_new_project_from_a_bus_scan(page: Page, demo_server: DemoServer) -> None:
    page.goto(demo_server.url + "/")
    page.get_by_test_id("new-project").click()
    page.get_by_test_id("new-project-name").fill("line2")
    page.get_by_test_id("new-project-description").fill("Press line 2")
    page.get_by_test_id("create-project").click()
    expect(page.get_by_test_id("project-title")).to_have_text("line2")

    page.get_by_role("link", name="Bus and scan").click()
    page.get_by_test_id(f"scan-{demo_server.bus}").click()
    node = demo_server.axes[2][1]
    row = page.get_by_test_id(f"scan-node-{node}")
    expect(row).to_contain_text("xtrapulspac")
    screenshot(page, "bus-scan")
    page.get_by_test_id(f"add-node-{node}").click()
    page.get_by_test_id("add-project").select_option("line2")
    page.get_by_test_id("add-confirm").click()
    expect(page.get_by_test_id("project-title")).to_have_text("line2")
    expect(page.get_by_test_id("axes-table")).to_contain_text(f"xtrapulspac-{node}")
    project = demo_server.api("GET", "/api/projects/line2").json()
    assert [(a["name"], a["node_id"], a["device"]) for a in project["axes"]] == [
        (f"xtrapulspac-{node}", node, "xtrapulspac")
    ]
    expect(page.get_by_test_id(f"tree-state-xtrapulspac-{node}")).not_to_have_text("offline")
    page.get_by_test_id("commission-check").click()
    expect(page.get_by_test_id("commission-result")).to_have_text("check: every axis OK")
    screenshot(page, "project-page")


def test_dialog_terminal_reads_and_writes(page: Page, demo_server: DemoServer) -> None:
    page.goto(demo_server.url + "/terminal")
    objects = page.get_by_test_id("terminal-object")
    expect(objects).to_have_count(4)
    page.get_by_test_id("terminal-read").click()
    expect(page.get_by_test_id("terminal-value").first).to_have_text(re.compile(r"^\d+$"))
    objects.nth(3).fill("0x6083")
    objects.nth(3).dispatch_event("change")
    page.get_by_test_id("terminal-input").nth(3).fill("12345")
    page.get_by_test_id("terminal-write").nth(3).click()
    expect(page.get_by_test_id("terminal-value").nth(3)).to_have_text("12345")
    expect(page.get_by_test_id("terminal-log")).to_contain_text("write")
    screenshot(page, "terminal")


def test_backup_into_the_project_then_checklist_and_compare(page: Page, demo_server: DemoServer) -> None:
    axis, node = demo_server.axes[2]
    page.goto(f"{demo_server.url}/projects/demo/axes/{axis}/backup")
    page.get_by_test_id("backup-to-project").click()
    page.get_by_test_id("confirm").click()  # the summary of what changes (tests/browser/test_first_use_backup.py)
    expect(page.get_by_test_id("backup-result")).to_contain_text(f"of node {node} stored in project demo")
    screenshot(page, "backup")
    rows = demo_server.api("GET", f"/api/projects/demo/axes/{axis}/parameters?only_set=true").json()["parameters"]
    assert len(rows) > 100

    page.get_by_test_id("tab-commissioning").click()
    expect(page.get_by_test_id("step-tuning")).to_have_attribute("data-state", re.compile("done|partial"))
    screenshot(page, "commissioning")

    page.goto(f"{demo_server.url}/projects/demo/compare")
    page.get_by_test_id(f"compare-axis-{axis}").check()
    expect(page.get_by_test_id("compare-table")).to_be_visible()
    expect(page.get_by_test_id("compare-summary")).to_contain_text("differ")
    screenshot(page, "compare")


def test_archive_and_import_under_a_new_name(page: Page, demo_server: DemoServer, tmp_path) -> None:
    page.goto(f"{demo_server.url}/projects/demo")
    with page.expect_download() as download_info:
        page.get_by_test_id("archive").click()
    archive = tmp_path / "demo.zip"
    download_info.value.save_as(archive)
    assert archive.read_bytes()[:2] == b"PK"

    page.goto(demo_server.url + "/")
    with page.expect_file_chooser() as chooser:
        page.get_by_test_id("unarchive").click()
    chooser.value.set_files(str(archive))
    page.get_by_test_id("import-name").fill("demo-restored")
    page.get_by_test_id("import-confirm").click()
    expect(page.get_by_test_id("project-title")).to_have_text("demo-restored")
    restored = demo_server.api("GET", "/api/projects/demo-restored").json()
    assert [a["name"] for a in restored["axes"]] == [name for name, _node in demo_server.axes]


def test_a_scan_that_finds_nothing_says_so_and_why(page: Page, demo_server: DemoServer) -> None:
    """#14 point 13: an empty bus is an answer, with the reasons the server gives for its kind (X-Scan-Hint)."""
    page.goto(demo_server.url + "/")
    page.get_by_role("link", name="Bus and scan").click()
    page.get_by_test_id("bus-spec").fill("virtual:nobody-here")
    page.get_by_test_id("bus-id").fill("empty")
    page.get_by_test_id("bus-connect").click()
    page.get_by_test_id("scan-empty").click()
    hint = page.get_by_test_id("scan-hint")
    expect(hint).to_contain_text("No node answered on empty.")
    expect(hint).to_contain_text("virtual")  # the hint for a virtual channel: another process's channel is not this one
    demo_server.api("DELETE", "/api/buses/empty")
