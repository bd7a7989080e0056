"""The controller panel and the audit log view against a real server: a second page sees who holds the axis and
asks for it, the holder is asked and releases, and the audit page lists what happened, filtered by axis."""

from playwright.sync_api import Page, expect
from tests.support.browser import DemoServer


def test_a_second_page_asks_the_holder_and_the_audit_log_shows_it(page: Page, browser, demo_server: DemoServer) -> None:
    axis, node = demo_server.axes[0]
    page.goto(f"{demo_server.url}/projects/demo/axes/{axis}")
    page.get_by_test_id("control-arm").click()
    expect(page.get_by_test_id("controller-holder")).to_have_text("Armed by this page")

    other = browser.new_context(viewport={"width": 1366, "height": 768}).new_page()
    other.goto(f"{demo_server.url}/projects/demo/axes/{axis}")
    expect(other.get_by_test_id("controller-holder")).to_contain_text("Armed by local")
    other.get_by_test_id("control-request").click()
    expect(page.get_by_test_id("controller-asked")).to_contain_text("asks for this axis")
    page.get_by_test_id("control-hand-over").click()
    expect(other.get_by_test_id("control-arm")).to_be_visible()  # the release reached the other page as an event
    other.context.close()

    page.goto(f"{demo_server.url}/audit?axis={demo_server.bus}:{node}")
    table = page.get_by_test_id("audit-table")
    expect(table).to_contain_text("release")
    expect(table).to_contain_text("request")
    expect(table).to_contain_text("arm")
    expect(page.get_by_test_id("audit-filter-axis")).to_have_value(f"{demo_server.bus}:{node}")
    page.get_by_test_id("audit-filter-action").fill("arm")
    page.get_by_test_id("audit-apply").click()
    rows = table.locator("tbody tr")  # other tests on the shared server may have armed this axis before: not counted
    expect(rows.filter(has_text="request")).to_have_count(0)
    expect(rows.filter(has_text="release")).to_have_count(0)
    expect(rows.first).to_contain_text("arm")
    with page.expect_download() as download:
        page.get_by_test_id("audit-export-csv").click()
    assert download.value.suggested_filename == "audit.csv"
