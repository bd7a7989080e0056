"""The sequence editor: build a two-sequence program in the table and fields, see it in the chaining graph, save it as
the project's SEQUENCE.TXT, write it to the simulated drive, run it as the armed controller and see the timeline."""

from __future__ import annotations

import re

from playwright.sync_api import Page, expect
from tests.support.browser import DemoServer, screenshot

REV = 4096


def fill(page: Page, testid: str, value: str) -> None:
    field = page.get_by_test_id("sequence-fields").get_by_test_id(testid)
    field.fill(value)
    field.press("Tab")


def build_sequence(page: Page, number: int, kind: str, values: dict[str, str]) -> None:
    page.get_by_test_id(f"sequence-type-{number}").select_option(kind)
    expect(page.get_by_test_id("sequence-fields")).to_contain_text(f"Sequence {number}: {kind}")
    for keyword, value in values.items():
        if keyword in ("PosType", "Trigger"):
            page.get_by_test_id("sequence-fields").get_by_test_id(f"field-{keyword}").select_option(value)
        else:
            fill(page, f"field-{keyword}", value)


def test_a_two_sequence_program_is_built_graphed_downloaded_and_run(page: Page, demo_server: DemoServer):
    axis, _ = demo_server.axes[2]
    page.goto(f"{demo_server.url}/projects/demo/axes/{axis}/sequences")
    expect(page.get_by_test_id("sequence-table")).to_be_visible()
    move = {"PosType": "REL", "Pos": str(REV // 4), "Speed": str(20 * REV), "Accel": str(400 * REV)}
    build_sequence(page, 1, "POS", {**move, "Decel": str(400 * REV), "Tempo": "10", "Trigger": "BEGIN", "SeqNext": "2"})
    build_sequence(page, 2, "SPEED", {"Speed": str(2 * REV), "AccelTime": "20", "DecelTime": "20", "RunTime": "50"})
    page.get_by_test_id("sequence-row-1").click()
    page.get_by_test_id("pattern-Output-bit3").click()  # Output "....1...": set output 4 at BEGIN
    expect(page.get_by_test_id("pattern-Output-bit3")).to_contain_text("1")

    graph = page.get_by_test_id("sequence-graph")
    expect(graph.get_by_test_id("graph-edge-1-2-next")).to_be_attached()
    expect(graph.get_by_test_id("graph-node-2")).to_have_attribute("data-type", "SPEED")
    expect(page.get_by_test_id("graph-findings")).to_contain_text("No findings")

    page.get_by_test_id("sequence-save").click()
    expect(page.get_by_test_id("sequence-dirty")).to_have_text("saved")
    saved = demo_server.api("GET", f"/api/projects/demo/axes/{axis}/sequences").json()["text"]
    assert "SeqNb=1\nSeqType=POS\nPosType=REL\n" in saved and 'Output="....1..."' in saved
    assert "SeqNb=2\nSeqType=SPEED" in saved

    page.get_by_test_id("sequence-arm").click()
    expect(page.get_by_test_id("sequence-holder")).to_have_text("Armed by this page")
    page.get_by_test_id("sequence-write").click()
    expect(page.get_by_test_id("sequence-message")).to_have_text("Written to the drive and verified")
    page.get_by_test_id("sequence-start-number").fill("1")
    page.get_by_test_id("sequence-start").click()
    timeline = page.get_by_test_id("sequence-timeline")
    expect(timeline.get_by_test_id("timeline-entry")).to_have_count(2, timeout=15000)
    expect(page.get_by_test_id("monitor-sequence")).to_have_text("no program", timeout=15000)
    entries = timeline.get_by_test_id("timeline-entry")
    expect(entries.nth(0)).to_have_attribute("data-sequence", "1")
    expect(entries.nth(1)).to_have_attribute("data-sequence", "2")
    expect(entries.nth(1)).to_have_text(re.compile(r"sequence 2 \(END\)"))
    expect(page.get_by_test_id("monitor-outputs")).to_have_text("00001000")  # output 4, set at BEGIN of sequence 1
    screenshot(page, "sequence-editor")
    page.get_by_test_id("sequence-release").click()
    expect(page.get_by_test_id("sequence-arm")).to_be_visible()
