"""A TTA-PRO's backup page in Chromium against a simulated PROFIBUS-DP slave (docs/ui.md, docs/profibus.md §10,
§13): the axis shows only the tabs its device can use (the dictionary's ``features``: none for a TTA-PRO); the page
lists the drive's own files, TTAPAR.TXT and TTASEQ.TXT; "Back up to PC" of TTASEQ.TXT downloads the sequences the
slave's EEPROM holds; "Store parameters" says what it writes (PNU 729 = 1, not CANopen's 0x1010) and the value
written before it survives a simulated power cycle (which keeps only EEPROM values) — judged on the slave.

The server runs in this process (``tests/support/ttapro_ui.py``) so the test reaches the slave itself."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from playwright.sync_api import Page, expect
from tests.support.browser import screenshot
from tests.support.ttapro_ui import NODE, TtaProServer, ttapro_ui_server

SHOWN = ["dashboard", "parameters", "commissioning", "backup"]
HIDDEN = ["scope", "current-loop", "phasing", "tuning", "bode", "sequences", "io"]
FIELDS = range(782, 795)  # the sequence buffer's fields (docs/profibus.md §13)
SEQUENCE = 7


@pytest.fixture(scope="module")
def server(tmp_path_factory) -> Iterator[TtaProServer]:
    with ttapro_ui_server(tmp_path_factory.mktemp("ttapro-backup-ui")) as running:
        yield running


def eeprom_lines(server: TtaProServer) -> list[str]:
    """Sequence 7 put into the slave's EEPROM (its checksum updated), as TTASEQ.TXT's lines say it."""
    with server.line.line.lock:
        sequences = server.line.slaves[NODE].sequences
        values = {782: 1, 783: 4321, 784: 900, 785: 50, 786: 60, 787: 70, 788: -1}
        sequences.eeprom[SEQUENCE] = {**sequences.eeprom[SEQUENCE], **values}
        sequences.stored_checksum = sequences.checksum()
        return [f"{pnu},{SEQUENCE}={sequences.eeprom[SEQUENCE][pnu]}" for pnu in FIELDS]


def test_a_ttapro_backup_page_lists_its_files_downloads_its_sequences_and_stores(
    page: Page, server: TtaProServer
) -> None:
    expected = eeprom_lines(server)
    page.goto(f"{server.url}/projects/pb/axes/X/backup")
    for view in SHOWN:
        expect(page.get_by_test_id(f"tab-{view}")).to_be_visible()
    for view in HIDDEN:
        expect(page.get_by_test_id(f"tab-{view}")).to_have_count(0)
    expect(page.locator("table.data td.mono")).to_have_text(["TTAPAR.TXT", "TTASEQ.TXT"])

    with page.expect_download(timeout=15_000) as download:
        page.get_by_test_id("download-TTASEQ.TXT").click()
    assert download.value.suggested_filename == "X_TTASEQ.TXT"
    lines = download.value.path().read_text(encoding="latin-1").splitlines()
    assert lines[0].startswith(f"; TTASEQ.TXT of node {NODE} (TTA-PRO)")
    assert lines[1:] == expected
    expect(page.get_by_test_id("backup-result")).to_contain_text("TTASEQ.TXT of node 5 saved as X_TTASEQ.TXT")

    kept = server.line.slaves[NODE].memory.get(730) % 300 + 41
    server.api("PUT", f"/buses/pb/nodes/{NODE}/objects/PNU730", json={"value": kept})
    expect(page.get_by_test_id("store-action")).to_contain_text("PNU 729 Save parameters in EEPROM = 1")
    expect(page.get_by_test_id("store-action")).not_to_contain_text("0x1010")
    page.get_by_test_id("store-flash").click()
    expect(page.get_by_test_id("backup-result")).to_have_text(
        "Node 5 stored its parameters (PNU 729 Save parameters in EEPROM = 1)."
    )
    with server.line.line.lock:
        server.line.slaves[NODE].power_cycle()
        assert server.line.slaves[NODE].memory.get(730) == kept  # the power cycle rebuilt the memory from EEPROM
    screenshot(page, "ttapro-backup")


def test_a_tab_the_ttapro_cannot_use_says_so_when_reached_by_its_address(page: Page, server: TtaProServer) -> None:
    page.goto(f"{server.url}/projects/pb/axes/X/scope")
    expect(page.get_by_test_id("view-unavailable")).to_contain_text("Scope: the TTA-PRO (PROFIBUS-DP) does not have it")
    expect(page.get_by_test_id("tab-scope")).to_have_count(0)
