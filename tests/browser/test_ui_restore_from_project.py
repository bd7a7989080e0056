"""Issue 14 point 5: "Restore project to drive" sends the project's values as the drive's own file, one restore job on
the server (validated, written, verified, stored — the path of ``servostudio restore``), not one REST write per
value from the browser."""

import re

from playwright.sync_api import Page, expect
from tests.support.browser import DemoServer


def test_restore_project_to_drive_runs_one_server_job(page: Page, demo_server: DemoServer) -> None:
    axis, node = demo_server.axes[2]
    drive = f"/api/buses/{demo_server.bus}/nodes/{node}/objects/0x6068,0"
    on_drive = demo_server.api("GET", drive).json()["raw"]
    demo_server.api("PUT", f"/api/projects/demo/axes/{axis}/parameters", json={"values": {"0x6068": on_drive + 5}})
    object_writes: list[str] = []
    page.on(
        "request",
        lambda request: request.method == "PUT" and "/objects/" in request.url and object_writes.append(request.url),
    )
    page.goto(f"{demo_server.url}/projects/demo/axes/{axis}/backup")
    page.get_by_test_id("restore-from-project").click()
    expect(page.get_by_role("dialog")).to_contain_text("store them to flash")
    page.get_by_test_id("confirm").click()
    result = page.get_by_test_id("backup-result").locator(".message")
    expect(result).to_contain_text(re.compile(rf"DRIVEPAR.TXT restored to node {node}: \d+ verified"))
    assert demo_server.api("GET", drive).json()["raw"] == on_drive + 5
    assert object_writes == []  # the values went in one job, not one request each
    demo_server.api("PUT", drive, json={"value": on_drive})
    demo_server.api("PUT", f"/api/projects/demo/axes/{axis}/parameters", json={"values": {"0x6068": on_drive}})
