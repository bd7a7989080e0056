"""The I/O page configures a limit switch on each simulated device and sees the drive react: on the XtrapulsPac an
input's function and polarity (a normally-open limit is flagged unsafe; inverted, the missing 24 V activates the
limit until the test bench wires it) and an output's source and polarity; on the CD1-k the dedicated LS+ function
(freed, the drive no longer stops there); on the encoTRive, whose manual has nothing to configure, its live inputs."""

from __future__ import annotations

import re
from collections.abc import Iterator

import pytest
from playwright.sync_api import Page, expect
from tests.support.browser import DemoServer, screenshot

BUS, SPEC = "iobus", "sim:11:cd1k,12:encotrive"
ON = re.compile(r"\bon\b")


@pytest.fixture(scope="module")
def io_project(demo_server: DemoServer) -> Iterator[str]:
    """A project with the demo's XtrapulsPac node 1 and a second simulated bus with a CD1-k and an encoTRive."""
    demo_server.api("POST", "/api/buses", json={"spec": SPEC, "id": BUS})
    buses = [{"name": "sim", "interface": "sim"}, {"name": BUS, "interface": SPEC}]
    demo_server.api("POST", "/api/projects", json={"name": "io", "buses": buses})
    for name, device, node, bus in (
        ("P", "xtrapulspac", 1, "sim"),
        ("C", "cd1k", 11, BUS),
        ("E", "encotrive", 12, BUS),
    ):
        demo_server.api(
            "POST", "/api/projects/io/axes", json={"name": name, "device": device, "node_id": node, "bus": bus}
        )
    yield "io"
    reset = {
        "inputs": [{"name": "IN3", "function": "none", "inverted": False}],
        "outputs": [{"name": "OUT1", "function": "none", "inverted": False}],
    }
    demo_server.api("PUT", f"/api/buses/{demo_server.bus}/nodes/1/io", json=reset)
    demo_server.api("PUT", f"/api/buses/{demo_server.bus}/nodes/1/io/sim-inputs", json={"value": 0})
    demo_server.api("DELETE", f"/api/buses/{BUS}")


def open_io(page: Page, server: DemoServer, axis: str) -> None:
    page.goto(f"{server.url}/projects/io/axes/{axis}/io")
    expect(page.get_by_test_id("io-page")).to_be_visible()


def write(page: Page, written: str) -> None:
    page.get_by_test_id("io-write").click()
    expect(page.get_by_test_id("io-message")).to_contain_text(written)


def test_xtrapulspac_limit_switch_function_and_polarity(page: Page, demo_server: DemoServer, io_project: str):
    open_io(page, demo_server, "P")
    limit = page.get_by_test_id("io-acts-positive_limit")
    page.get_by_test_id("io-input-IN3-function").select_option("positive_limit")
    write(page, "0x3050,3")
    expect(page.get_by_test_id("io-finding-unsafe")).to_contain_text("IN3 is the positive limit switch with normal")
    expect(limit).not_to_have_class(ON)  # normal polarity, no 24 V: inactive
    page.get_by_test_id("io-input-IN3-inverted").check()
    write(page, "0x3051,0")
    expect(page.get_by_test_id("io-finding-unsafe")).to_have_count(0)
    expect(limit).to_have_class(ON)  # fail-safe: no 24 V on the inverted input stops the positive direction
    expect(page.get_by_test_id("io-input-IN3-live")).to_have_text("active")
    page.get_by_test_id("io-bench-IN3").check()  # the test bench wires 24 V: a closed NC switch
    expect(limit).not_to_have_class(ON)
    expect(page.get_by_test_id("io-findings")).not_to_contain_text("is active now")
    page.get_by_test_id("io-output-OUT1-function").select_option("fault")  # OUT1 ← status word bit 3, inverted:
    page.get_by_test_id("io-output-OUT1-inverted").check()  # on while the drive has no fault
    write(page, "0x3054,1")
    expect(page.get_by_test_id("io-output-OUT1-live")).to_have_text("active")
    screenshot(page, "io-page-xtrapulspac")
    page.get_by_test_id("tab-dashboard").click()  # the dashboard names the input by its configuration
    expect(page.get_by_test_id("io-inputs")).to_contain_text("IN3 LIM+")


def test_cd1k_dedicated_limit_switch(page: Page, demo_server: DemoServer, io_project: str):
    open_io(page, demo_server, "C")
    limit = page.get_by_test_id("io-acts-positive_limit")
    expect(page.get_by_test_id("io-input-INPUT0-inverted")).to_have_count(0)  # no polarity object
    page.get_by_test_id("io-bench-INPUT0").check()  # LS+ active
    expect(limit).to_have_class(ON)
    page.get_by_test_id("io-input-INPUT0-function").select_option("general")
    write(page, "0x30FD,0")
    expect(limit).not_to_have_class(ON)  # freed: the drive no longer stops there
    expect(page.get_by_test_id("io-finding-unsafe")).to_contain_text("freed for general use")
    expect(page.get_by_test_id("io-input-INPUT0-live")).to_have_text("active")
    page.get_by_test_id("io-input-INPUT0-function").select_option("positive_limit")
    write(page, "0x30FD,0")
    expect(limit).to_have_class(ON)
    page.get_by_test_id("io-bench-INPUT0").uncheck()
    expect(limit).not_to_have_class(ON)
    page.get_by_test_id("tab-dashboard").click()  # its terminals named once each, from the I/O configuration,
    terminals = page.get_by_test_id("io-inputs").locator(".led")  # apart from what the drive makes of them
    expect(terminals).to_have_text(["INPUT0 LIM+", "INPUT1 LIM−", "INHIBIT", "INPUT3 INDEX", "INPUT4 CAPTURE",
                                    "INPUT5 LOW"])  # fmt: skip
    expect(page.get_by_test_id("io-inputs-functions").locator(".led")).to_have_text(["LIM−", "LIM+", "Home", "Inhibit"])


def test_encotrive_shows_its_inputs_without_configuration(page: Page, demo_server: DemoServer, io_project: str):
    open_io(page, demo_server, "E")
    expect(page.get_by_test_id("io-inputs-none")).to_be_visible()
    expect(page.get_by_test_id("io-note")).to_contain_text("no object to give an input a function or a polarity")
    expect(page.get_by_test_id("io-bench")).to_have_count(0)
    expect(page.get_by_test_id("io-acts-on")).to_be_visible()
