"""Parameter editor against the real server and simulated drives (the issue's acceptance test)."""

from playwright.sync_api import Page, expect
from tests.support.browser import DemoServer, screenshot, xtrapulspac_entries

ENTRIES = xtrapulspac_entries()


def test_kpv_found_changed_on_the_drive_and_persisted(page: Page, demo_server: DemoServer) -> None:
    axis, node = demo_server.axes[0]
    page.goto(demo_server.url + "/")
    page.get_by_test_id("tree-project-demo").click()
    expect(page.get_by_test_id("project-title")).to_have_text("demo")
    page.get_by_test_id(f"axis-row-{axis}").get_by_role("link", name="Parameters").click()
    search = page.get_by_test_id("param-search")
    search.fill("KPv")
    row = page.locator('.prow.entry[data-address="0x60F9.2"]')
    expect(row).to_be_visible()
    expect(page.get_by_test_id("param-count")).to_have_text(f"1 of {ENTRIES} entries")
    row.click()
    before = demo_server.api(
        "GET", f"/api/buses/{demo_server.bus}/nodes/{node}/objects/0x60F9,2?device=xtrapulspac"
    ).json()["raw"]
    expect(page.get_by_test_id("detail-drive-value")).to_have_text(str(before))
    new_value = before + 111 if before < 60000 else before - 111
    page.get_by_test_id("target-both").check()  # an edit goes to the project only unless the drive is chosen
    editor = page.get_by_test_id("param-editor")
    editor.fill(str(new_value))
    page.get_by_test_id("param-write").click()
    expect(page.get_by_test_id("detail-drive-value")).to_have_text(str(new_value))
    screenshot(page, "parameters-kpv-written")

    on_drive = demo_server.api(
        "GET", f"/api/buses/{demo_server.bus}/nodes/{node}/objects/0x60F9,2?device=xtrapulspac"
    ).json()
    assert on_drive["raw"] == new_value
    in_project = demo_server.api("GET", f"/api/projects/demo/axes/{axis}/parameters/0x60F9,2").json()
    assert in_project["value"] == new_value and in_project["file"] == "DRIVEPAR.TXT"

    page.reload()
    expect(page.get_by_test_id("param-search")).to_have_value("KPv")
    page.locator('.prow.entry[data-address="0x60F9.2"]').click()
    expect(page.get_by_test_id("detail-drive-value")).to_have_text(str(new_value))
    expect(page.get_by_test_id("detail-project-value")).to_contain_text(f"{new_value} (DRIVEPAR.TXT)")


def test_decimal_point_in_a_german_browser_and_the_server_range_check(page: Page, demo_server: DemoServer) -> None:
    """The browser runs de-DE: "2,5" is refused with a reason, "2.5" A is written as raw 2500 mA."""
    axis, node = demo_server.axes[2]
    page.goto(f"{demo_server.url}/projects/demo/axes/{axis}/parameters?q=0x6075")
    page.locator('.prow.entry[data-address="0x6075"]').click()
    page.get_by_test_id("target-drive").check()
    editor = page.get_by_test_id("param-editor")
    editor.fill("2,5")
    editor.press("Enter")
    expect(page.get_by_test_id("param-error")).to_have_text('"2,5": use "." as decimal separator')
    editor.fill("2.5")
    editor.press("Enter")
    expect(page.get_by_test_id("detail-drive-value")).to_have_text("2.5 A  (raw 2500)")
    raw = demo_server.api(
        "GET", f"/api/buses/{demo_server.bus}/nodes/{node}/objects/0x6075,0?device=xtrapulspac"
    ).json()["raw"]
    assert raw == 2500
    screenshot(page, "parameters-scaled-value")


def test_only_differences_then_write_changed_to_the_drive(page: Page, demo_server: DemoServer) -> None:
    """A project value that differs from the drive is found among every entry of a group and written in bulk."""
    axis, node = demo_server.axes[0]
    drive_path = f"/api/buses/{demo_server.bus}/nodes/{node}/objects/0x60F9,3?device=xtrapulspac"
    wanted = demo_server.api("GET", drive_path).json()["raw"] + 7
    demo_server.api("PUT", f"/api/projects/demo/axes/{axis}/parameters", json={"values": {"0x60F9,3": wanted}})
    page.goto(f"{demo_server.url}/projects/demo/axes/{axis}/parameters?group=Servo+Loops")
    page.get_by_test_id("param-only-diff").check()
    row = page.locator('.prow.entry[data-address="0x60F9.3"]')
    expect(row).to_be_visible()
    expect(row.locator('[data-col="drive"] .differs')).to_be_visible()
    screenshot(page, "parameters-differences")
    page.get_by_test_id("param-write-changed").click()
    page.get_by_test_id("confirm").click()  # the list of what is written (tests/browser/test_first_use_editor.py)
    expect(page.get_by_test_id("toast").last).to_contain_text("written to the drive")
    assert demo_server.api("GET", drive_path).json()["raw"] == wanted
    expect(row.locator('[data-col="drive"]')).to_have_text(str(wanted))


def test_application_template_limits_the_editor_to_its_groups(page: Page, demo_server: DemoServer) -> None:
    """Device Config (manual §1.8.1): after choosing a template the editor opens on that application's groups."""
    demo_server.api("POST", "/api/projects", json={"name": "templated", "buses": [{"name": "sim", "interface": "sim"}]})
    demo_server.api(
        "POST", "/api/projects/templated/axes", json={"name": "A", "device": "xtrapulspac", "node_id": 1, "bus": "sim"}
    )
    chosen = demo_server.api("POST", "/api/projects/templated/axes/A/application", json={"template": "analog-speed"})
    template = demo_server.api("GET", "/api/projects/templated/axes/A/application").json()
    assert chosen.is_success and template["groups"]

    page.goto(f"{demo_server.url}/projects/templated/axes/A/parameters")
    group = page.get_by_test_id("param-group")
    expect(group).to_have_value("@application")
    count = page.get_by_test_id("param-count")
    expect(count).not_to_have_text(f"{ENTRIES} of {ENTRIES} entries")
    shown = {text for text in page.locator(".prow.group").all_inner_texts()}
    assert shown and all(any(name in text for name in template["groups"]) for text in shown), shown

    group.select_option("")  # All groups (Expert)
    expect(count).to_have_text(f"{ENTRIES} of {ENTRIES} entries")
    page.reload()
    expect(page.get_by_test_id("param-group")).to_have_value("")
    screenshot(page, "parameters-application-groups")
