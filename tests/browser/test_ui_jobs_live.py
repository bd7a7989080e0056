"""Cancel buttons of server jobs and live axis states in the tree, clicked against the real server."""

import re

from playwright.sync_api import Page, expect
from tests.support.browser import DemoServer

ATTEMPTS = 3


def test_cancel_a_file_restore_job(page: Page, demo_server: DemoServer, tmp_path) -> None:
    axis, node = demo_server.axes[0]
    drivepar = tmp_path / "DRIVEPAR.TXT"
    drivepar.write_bytes(
        demo_server.api("GET", f"/api/buses/{demo_server.bus}/nodes/{node}/files/DRIVEPAR.TXT").content
    )
    page.goto(f"{demo_server.url}/projects/{demo_server.project}/axes/{axis}/backup")
    result = page.get_by_test_id("backup-result")
    # The job may end before the click reaches the server; then it reports a full restore, and we try again.
    for _ in range(ATTEMPTS):
        with page.expect_file_chooser() as chooser:
            page.get_by_test_id("upload-DRIVEPAR.TXT").click()
        chooser.value.set_files(str(drivepar))
        page.get_by_test_id("confirm").click()
        page.get_by_test_id("backup-cancel").click()
        expect(result).to_contain_text("Restoring DRIVEPAR.TXT")
        if "cancelled" in result.inner_text():
            break
        expect(result).to_contain_text("verified")
    expect(result).to_have_text(
        re.compile(
            rf"Restoring DRIVEPAR\.TXT cancelled\. restore of node {node} cancelled: \d+ of \d+ objects were written"
            r".*nothing was stored to flash \(.*not written.*\)"
        )
    )
    jobs = demo_server.api("GET", "/api/jobs").json()
    assert jobs[-1]["operation"] == "restore" and jobs[-1]["state"] == "cancelled"
    assert jobs[-1]["result"][str(node)][0]["stored"] == ""


def test_tree_follows_a_state_change_made_elsewhere(page: Page, demo_server: DemoServer) -> None:
    """A control word written by another client changes the tree's axis state through drive_state events: the
    tree no longer polls while its event socket is open."""
    axis, node = demo_server.axes[-1]
    controlword = f"/api/buses/{demo_server.bus}/nodes/{node}/objects/controlword"
    demo_server.api("PUT", controlword, json={"value": 0})  # disable voltage: Switch on disabled
    page.goto(f"{demo_server.url}/projects/{demo_server.project}")
    tree_state = page.get_by_test_id(f"tree-state-{axis}")
    expect(tree_state).to_have_text("Switch on disabled")
    try:
        demo_server.api("PUT", controlword, json={"value": 6})  # shutdown
        expect(tree_state).to_have_text("Ready to switch on")
    finally:
        demo_server.api("PUT", controlword, json={"value": 0})
    expect(tree_state).to_have_text("Switch on disabled")
