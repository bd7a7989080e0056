"""Shell: deep links, keyboard shortcuts, help overlay, theme persisted across reloads."""

from pathlib import Path

from playwright.sync_api import Page, expect
from tests.support.browser import DemoServer, screenshot, xtrapulspac_entries

ENTRIES = xtrapulspac_entries()


def test_shortcuts_help_and_theme(page: Page, demo_server: DemoServer) -> None:
    axis, _node = demo_server.axes[0]
    page.goto(f"{demo_server.url}/projects/demo/axes/{axis}/commissioning")
    expect(page.get_by_test_id("checklist").locator("li")).to_have_count(12)
    page.keyboard.press("?")
    expect(page.get_by_test_id("help-overlay")).to_be_visible()
    expect(page.get_by_test_id("help-overlay")).to_contain_text("Parameters of the current axis")
    screenshot(page, "shortcuts-help")
    page.keyboard.press("Escape")
    expect(page.get_by_test_id("help-overlay")).to_have_count(0)

    page.keyboard.press("g")
    page.keyboard.press("p")
    expect(page).to_have_url(f"{demo_server.url}/projects/demo/axes/{axis}/parameters")
    expect(page.get_by_test_id("param-table")).to_be_visible()
    page.keyboard.press("/")
    expect(page.get_by_test_id("param-search")).to_be_focused()
    page.keyboard.type("KPv")
    expect(page.get_by_test_id("param-count")).to_have_text(f"1 of {ENTRIES} entries")
    page.get_by_test_id("param-search").press("Escape")

    page.keyboard.press("g")
    page.keyboard.press("d")
    expect(page).to_have_url(f"{demo_server.url}/projects/demo/axes/{axis}")
    page.go_back()
    expect(page).to_have_url(f"{demo_server.url}/projects/demo/axes/{axis}/parameters?q=KPv")
    expect(page.get_by_test_id("param-search")).to_have_value("KPv")

    theme = page.evaluate("document.documentElement.dataset.theme")
    page.get_by_test_id("theme-toggle").click()
    toggled = "dark" if theme == "light" else "light"
    page.reload()
    expect(page.locator("html")).to_have_attribute("data-theme", toggled)
    expect(page.locator('.prow.entry[data-address="0x60F9.2"]')).to_be_visible()
    screenshot(page, f"parameters-{toggled}-theme")


def test_dictionary_browser_and_error_pages(page: Page, demo_server: DemoServer) -> None:
    page.goto(f"{demo_server.url}/dictionaries/xtrapulspac")
    count = page.get_by_test_id("param-count")
    expect(count).to_have_text(f"{ENTRIES} of {ENTRIES} entries")
    page.get_by_test_id("param-group").select_option("Servo Loops")
    expect(count).not_to_have_text(f"{ENTRIES} of {ENTRIES} entries")
    assert "group=Servo+Loops" in page.url or "group=Servo%20Loops" in page.url
    page.get_by_test_id("param-search").fill("integral")
    expect(page.locator(".prow.entry").first).to_be_visible()
    assert 0 < page.locator(".prow.entry").count() < 40
    screenshot(page, "dictionary-filtered")

    page.goto(f"{demo_server.url}/projects/demo/axes/nonexistent")
    expect(page.get_by_test_id("page-error")).to_contain_text('Project demo has no axis "nonexistent"')
    page.goto(f"{demo_server.url}/no/such/page")
    expect(page.get_by_test_id("page-error")).to_have_text("There is no page at /no/such/page.")


def test_import_an_eds_and_browse_it(page: Page, demo_server: DemoServer, tmp_path) -> None:
    """A user EDS goes through the real import route; a broken one is refused with the loader's file:line reason."""
    source = Path(__file__).resolve().parents[2] / "eds"
    eds = tmp_path / "mydrive.eds"
    eds.write_text(
        (source / "encotrive.eds")
        .read_text(encoding="latin-1")
        .replace("ProductName=encoTRive MD-025", "ProductName=My drive"),
        encoding="latin-1",
    )
    page.goto(f"{demo_server.url}/dictionaries")
    page.get_by_test_id("import-eds").click()
    page.get_by_test_id("import-eds-file").set_input_files(str(eds))
    page.get_by_test_id("import-props-file").set_input_files(str(source / "encotrive.props"))
    page.get_by_test_id("import-confirm").click()
    row = page.get_by_test_id("dictionary-mydrive")
    expect(row).to_contain_text("My drive")
    expect(row).to_contain_text("imported")
    row.get_by_role("link", name="mydrive").click()
    expect(page.get_by_test_id("param-count")).to_contain_text(" entries")

    broken = tmp_path / "broken.eds"
    broken.write_text(
        "[FileInfo]\nFileName=broken.eds\n[1000]\nParameterName=Device type\nObjectType=0x7\n", encoding="latin-1"
    )
    page.goto(f"{demo_server.url}/dictionaries")
    page.get_by_test_id("import-eds").click()
    page.get_by_test_id("import-eds-file").set_input_files(str(broken))
    page.get_by_test_id("import-confirm").click()
    expect(page.get_by_test_id("dialog-error")).to_contain_text("broken.eds")
    screenshot(page, "dictionary-import-error")
