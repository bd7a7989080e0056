"""Issue 14, parameter editor: an edit goes to the project unless the user picks the drive, the field keeps the
value it was written to, "Write changed → drive" lists what it writes and what the filter hides, and values the
drive changes by itself (a procedure's status) follow the drive without Refresh."""

import re

from playwright.sync_api import Page, expect
from tests.support.browser import DemoServer, screenshot


def _drive(server: DemoServer, node: int, address: str) -> int:
    return server.api("GET", f"/api/buses/{server.bus}/nodes/{node}/objects/{address}?device=xtrapulspac").json()["raw"]


def _project(server: DemoServer, axis: str, address: str) -> dict:
    return server.api("GET", f"/api/projects/demo/axes/{axis}/parameters/{address}").json()


def _select(page: Page, server: DemoServer, axis: str, query: str, address: str) -> None:
    page.goto(f"{server.url}/projects/demo/axes/{axis}/parameters?q={query}")
    page.locator(f'.prow.entry[data-address="{address}"]').click()


def test_an_edit_goes_to_the_project_unless_the_drive_is_chosen_and_the_field_keeps_it(
    page: Page, demo_server: DemoServer
) -> None:
    axis, node = demo_server.axes[0]
    on_drive = _drive(demo_server, node, "0x6068,0")
    wanted = on_drive + 17 if on_drive < 30000 else on_drive - 17
    _select(page, demo_server, axis, "0x6068", "0x6068")
    expect(page.get_by_test_id("detail-drive-value")).to_have_text(f"{on_drive} ms")
    expect(page.get_by_test_id("target-project")).to_be_checked()
    write = page.get_by_test_id("param-write")
    expect(write).to_have_text("Write to project")
    editor = page.get_by_test_id("param-editor")
    editor.fill(str(wanted))
    write.click()
    expect(page.get_by_test_id("param-status")).to_have_text(
        f"0x6068 = {wanted} written to the project; the drive still holds {on_drive}"
    )
    assert _drive(demo_server, node, "0x6068,0") == on_drive  # the drive was not touched
    assert _project(demo_server, axis, "0x6068")["value"] == wanted
    # the field keeps what was written (the project's value), both values are shown, the field's one marked
    expect(editor).to_have_value(str(wanted))
    expect(page.get_by_test_id("editor-holds")).to_have_text("The field holds the project value.")
    expect(page.get_by_test_id("detail-project-value")).to_have_text(f"{wanted} ms (DRIVEPAR.TXT)")
    expect(page.get_by_test_id("detail-drive-value")).to_have_text(f"{on_drive} ms")
    expect(page.get_by_test_id("detail-project-label")).to_contain_text("field")
    screenshot(page, "first-use-project-write")

    page.get_by_test_id("target-drive").check()  # writing to the drive is a choice of its own, and says so
    expect(write).to_have_text("Write to drive")
    expect(editor).to_have_value(str(on_drive))
    expect(page.get_by_test_id("editor-holds")).to_have_text("The field holds the drive value.")
    editor.fill(str(wanted))
    write.click()
    expect(page.get_by_test_id("param-status")).to_have_text(
        f"0x6068 = {wanted} written to the drive; the project holds the same"
    )
    assert _drive(demo_server, node, "0x6068,0") == wanted
    page.reload()
    page.locator('.prow.entry[data-address="0x6068"]').click()
    expect(page.get_by_test_id("param-write")).to_have_text("Write to project")  # not remembered across visits


def test_write_changed_to_the_drive_lists_the_objects_and_what_the_filter_hides(
    page: Page, demo_server: DemoServer
) -> None:
    axis, node = demo_server.axes[2]
    shown_now = _drive(demo_server, node, "0x6067,0")
    hidden_now = _drive(demo_server, node, "0x6085,0")
    demo_server.api(
        "PUT",
        f"/api/projects/demo/axes/{axis}/parameters",
        json={"values": {"0x6067": shown_now + 9, "0x6085": hidden_now + 1000}},
    )
    page.goto(f"{demo_server.url}/projects/demo/axes/{axis}/parameters?group=Profile+Position+Mode")
    page.get_by_test_id("param-only-diff").check()
    expect(page.locator('.prow.entry[data-address="0x6067"]')).to_be_visible()
    expect(page.get_by_test_id("param-hidden-note")).to_contain_text("the filter hides")
    page.get_by_test_id("param-write-changed").click()
    change = page.locator('[data-testid="confirm-change"][data-address="0x6067"]')
    expect(change).to_contain_text(f"{shown_now}")
    expect(change).to_contain_text(f"{shown_now + 9}")
    expect(page.get_by_test_id("confirm-note")).to_contain_text("The filter hides")
    expect(page.get_by_test_id("confirm-note")).to_contain_text(
        "(1 of them differ from the drive): they are not written"
    )
    screenshot(page, "first-use-write-changed-confirm")
    page.get_by_test_id("confirm-cancel").click()
    assert _drive(demo_server, node, "0x6067,0") == shown_now  # cancelled: nothing written

    page.get_by_test_id("param-write-changed").click()
    page.get_by_test_id("confirm").click()
    expect(page.get_by_test_id("toast").last).to_contain_text("written to the drive")
    assert _drive(demo_server, node, "0x6067,0") == shown_now + 9
    assert _drive(demo_server, node, "0x6085,0") == hidden_now  # hidden by the filter: not written


def test_a_procedure_status_follows_the_drive_without_refresh(page: Page, demo_server: DemoServer) -> None:
    axis, _node = demo_server.axes[0]
    page.goto(f"{demo_server.url}/projects/demo/axes/{axis}")
    state = page.get_by_test_id("dashboard-state")
    expect(state).not_to_have_text("—")
    if state.inner_text() != "Switch on disabled":
        page.get_by_test_id("transition-disable_voltage").click()
    expect(state).to_have_text("Switch on disabled")
    page.get_by_test_id("control-arm").click()  # 'apha' turns the motor: it needs this page as the controller
    expect(page.get_by_test_id("controller-holder")).to_have_text("Armed by this page")
    page.get_by_test_id("tab-parameters").click()
    page.get_by_test_id("param-search").fill("3413")
    page.locator('.prow.entry[data-address="0x3413"]').click()
    expect(page.get_by_test_id("param-write")).to_have_text("Write to drive")  # the project does not hold it
    page.get_by_test_id("param-editor").select_option(value=str(0x61687061))
    page.get_by_test_id("param-write").click()
    status = page.get_by_test_id("detail-drive-value")
    expect(status).to_have_text(re.compile(r"Running \(2\)"))
    row = page.locator('.prow.entry[data-address="0x3413"] [data-col="drive"]')
    expect(status).to_have_text(re.compile(r"Done \(5\)"), timeout=60_000)  # no Refresh clicked
    expect(row).to_have_text("Done (5)")
    screenshot(page, "first-use-procedure-done")
