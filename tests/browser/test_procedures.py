"""The procedure pages against a simulated, uncommissioned XtrapulsPac on a hidden seeded plant (incremental encoder
without Hall sensors): the current loop calculated from the inductance typed in the page, I²t set to Fusing,
auto-phasing and auto-tuning run from the UI behind their safety checklists and the arm switch, their results
checked against the plant's true values, an aborted tuning leaving the gains as they were, Undo, the results kept in
the project, and after a 24 V-like reset the dashboard's warning bit 30 with its one-click motor phasing.

The simulator runs in its own process (`servostudio sim --plant`), the server reaches it over socketcand, as a
user's bench would be set up.
"""

from __future__ import annotations

import dataclasses
import json
import re
import subprocess
import sys
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import httpx
import pytest
from playwright.sync_api import Page, expect
from tests.support.browser import screenshot
from tests.support.live_server import REPO_ROOT, LiveServer

from servostudio.sim.plant import FEEDBACK_ENCODER, Plant

SEED = 20261202
PROCEDURE_TIMEOUT = 90_000  # ms: the simulated drive runs in real time on a shared machine
READ_TIMEOUT = 60_000  # ms: the list reads every procedure's preconditions from the drive over SDO


@dataclass(frozen=True)
class Rig:
    url: str
    bus: str
    plant: Plant

    def node(self, path: str = "") -> str:
        return f"{self.url}/api/buses/{self.bus}/nodes/1{path}"

    def raw(self, key: str) -> int:
        response = httpx.get(self.node(f"/objects/{key}"), timeout=15.0)
        assert response.is_success, response.text
        return response.json()["raw"]

    def write(self, key: str, value: int | str) -> None:
        response = httpx.put(self.node(f"/objects/{key}"), json={"value": value}, timeout=15.0)
        assert response.is_success, f"{key} = {value}: {response.text}"


def start_simulator(plant_file: Path) -> tuple[subprocess.Popen, str]:
    command = [sys.executable, "-m", "servostudio", "sim", "--nodes", "1", "--plant", str(plant_file)]
    process = subprocess.Popen([*command, "--socketcand", "127.0.0.1:0"], cwd=REPO_ROOT, stdout=subprocess.PIPE)
    assert process.stdout is not None
    described = json.loads(process.stdout.readline())
    return process, f"socketcand:127.0.0.1:{described['socketcand']['port']}"


@pytest.fixture(scope="module")
def rig(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Rig]:
    root = tmp_path_factory.mktemp("procedures")
    plant = dataclasses.replace(Plant.from_seed(SEED), feedback=FEEDBACK_ENCODER)
    plant.write_json(root / "plant.json")
    simulator, spec = start_simulator(root / "plant.json")
    projects = root / "projects"
    (projects / "rig").mkdir(parents=True)
    (projects / "rig" / "project.toml").write_text(
        f'[project]\nformat = 1\nname = "rig"\ndescription = "bench"\n\n[bus.rig]\ninterface = "{spec}"\n\n'
        '[axis.A]\ndevice = "xtrapulspac"\nnode_id = 1\nbus = "rig"\n',
        encoding="utf-8",
    )
    server = LiveServer(projects, ["--bus", spec])  # only this bus: no simulated drives in the server's process
    try:
        server.wait_ready(timeout=90.0)
        # `--bus` opened only this bus
        (bus,) = [item["id"] for item in httpx.get(f"{server.url}/api/buses", timeout=30.0).json()]
        rig = Rig(server.url, bus, plant)
        # The motor's datasheet values, as a user enters them before commissioning (the inductance comes in the page).
        rig.write("0x6410,9", round(plant.stall_current * 1000))
        rig.write("0x6410,10", round(plant.peak_current * 1000))
        rig.write("0x6410,11", round(plant.torque_constant * 1000))
        rig.write("0x6410,12", round(plant.motor_inertia * 1e6))
        yield rig
    finally:
        server.stop()
        simulator.terminate()
        simulator.wait(timeout=10)


def axis_page(page: Page, rig: Rig, view: str) -> None:
    page.goto(f"{rig.url}/projects/rig/axes/A{'/' + view if view else ''}")


def tick_checklist(page: Page, name: str) -> None:
    boxes = page.get_by_test_id(f"{name}-checklist").locator("input[type=checkbox]")
    for position in range(boxes.count()):
        boxes.nth(position).check()


def arm(page: Page) -> None:
    """Make this page the axis's controller (each test's page is a new browser context: a new client)."""
    holder = page.get_by_test_id("controller-holder")
    expect(holder).to_have_text(re.compile("^(Not armed|Armed by this page)"), timeout=READ_TIMEOUT)
    if holder.inner_text().startswith("Not armed"):
        page.get_by_test_id("control-arm").click()
    expect(holder).to_have_text("Armed by this page")


def number(text: str) -> float:
    return float(re.match(r"^\s*([-+0-9.e]+)", text).group(1))


def test_current_loop_from_the_inductance_typed_in_the_page(page: Page, rig: Rig) -> None:
    axis_page(page, rig, "current-loop")
    start = page.get_by_test_id("current_loop-start")
    inductance = page.get_by_test_id("current_loop-pre-value:control_inductance")
    expect(inductance).to_have_attribute("data-ok", "false", timeout=READ_TIMEOUT)
    expect(start).to_be_disabled()
    expect(page.get_by_test_id("current_loop-reason")).to_contain_text("Motor inductance for current loop is 0")
    page.get_by_test_id("cl-inductance").fill(f"{rig.plant.inductance * 1000:.2f}")  # phase to phase, mH
    expect(inductance).to_have_attribute("data-ok", "true")
    expect(start).to_be_enabled()  # 'calc' does not turn the motor: no arming needed
    start.click()
    expect(page.get_by_test_id("result-status")).to_have_text(re.compile("^Done"), timeout=PROCEDURE_TIMEOUT)
    kp = page.get_by_test_id("current-gains-kp_current_q").locator("td").nth(2)
    assert int(kp.inner_text()) == rig.raw("0x60F6,2") > 0
    assert rig.raw("0x340F,0") == round(rig.plant.inductance * 1e4)
    expect(page.get_by_test_id("limits-now")).not_to_have_text(re.compile("—"))

    page.get_by_test_id("i2t-select").select_option("1")
    page.get_by_test_id("i2t-apply").click()
    expect(page.get_by_test_id("i2t-mode")).to_have_text("Fusing (1)")
    assert rig.raw("0x3404,1") == 1
    expect(page.get_by_test_id("i2t-times")).to_contain_text("warning after")
    screenshot(page, "procedures-current-loop")


def test_auto_phasing_from_the_ui_finds_the_plants_commutation(page: Page, rig: Rig) -> None:
    axis_page(page, rig, "phasing")
    start = page.get_by_test_id("auto_phasing-start")
    expect(page.get_by_test_id("auto_phasing-pre-disabled")).to_have_attribute("data-ok", "true", timeout=READ_TIMEOUT)
    expect(start).to_be_disabled()
    expect(page.get_by_test_id("auto_phasing-reason")).to_contain_text("Tick the safety checklist first (5 left")
    tick_checklist(page, "auto_phasing")
    expect(page.get_by_test_id("auto_phasing-reason")).to_have_text(re.compile("^Arm the axis first"))
    expect(start).to_be_disabled()
    arm(page)
    expect(start).to_be_enabled()
    start.click()
    expect(page.get_by_test_id("auto_phasing-abort")).to_be_enabled()
    expect(page.get_by_test_id("procedure-phase")).to_be_visible()
    expect(page.get_by_test_id("result-status")).to_have_text(re.compile("^Done"), timeout=PROCEDURE_TIMEOUT)
    plant = rig.plant
    expect(page.get_by_test_id("result-pole-pairs")).to_have_text(re.compile(rf"→{plant.pole_pairs}$"))
    order = "0x5555 (240°" if plant.phase_order == 0x5555 else "0xAAAA (120°"
    expect(page.get_by_test_id("result-phase-order").locator("td").nth(3)).to_contain_text(order)
    expect(page.get_by_test_id("phasing-verification")).to_have_attribute("data-passed", "true")
    assert (rig.raw("0x3410,1"), rig.raw("0x3410,2")) == (plant.pole_pairs, plant.phase_order)
    expect(page.get_by_test_id("saved-results").get_by_test_id("saved-row").first).to_contain_text("auto_phasing")
    screenshot(page, "procedures-phasing")


def release_brake(page: Page) -> None:
    """Auto-tuning does not control the brake: the page's remedy releases it by manual brake control (confirmed)."""
    precondition = page.get_by_test_id("auto_tuning-pre-brake_released")
    expect(precondition).to_have_attribute("data-ok", re.compile("true|false"), timeout=READ_TIMEOUT)
    if precondition.get_attribute("data-ok") == "false":
        page.get_by_test_id("brake-release").click()
        page.get_by_test_id("confirm").click()
        expect(page.get_by_test_id("brake-released")).to_be_visible()
    expect(precondition).to_have_attribute("data-ok", "true")


def tuning_options(page: Page) -> None:
    page.get_by_test_id("tune-bandwidth").select_option("75")
    page.get_by_test_id("tune-filter").select_option("standard")
    page.get_by_test_id("tune-mode").select_option("min-following-error")
    tick_checklist(page, "auto_tuning")


def test_an_aborted_tuning_leaves_the_gains_as_they_were(page: Page, rig: Rig) -> None:
    gains = ("0x60F9,2", "0x60F9,3", "0x60FB,2")
    before = [rig.raw(key) for key in gains]
    axis_page(page, rig, "tuning")
    arm(page)
    release_brake(page)
    tuning_options(page)
    page.get_by_test_id("auto_tuning-start").click()
    expect(page.get_by_test_id("procedure-phase")).to_have_text("running")
    page.get_by_test_id("auto_tuning-abort").click()
    expect(page.get_by_test_id("procedure-aborted")).to_be_visible(timeout=PROCEDURE_TIMEOUT)
    assert [rig.raw(key) for key in gains] == before
    assert httpx.get(rig.node("/state"), timeout=15.0).json()["state"] != "OPERATION ENABLED"


def test_auto_tuning_from_the_ui_identifies_the_plant_verifies_and_undoes(page: Page, rig: Rig) -> None:
    axis_page(page, rig, "tuning")
    release_brake(page)  # stays released from the test before
    before = rig.raw("0x60F9,2")
    arm(page)
    tuning_options(page)
    page.get_by_test_id("auto_tuning-start").click()
    expect(page.get_by_test_id("result-status")).to_have_text(re.compile("^Done"), timeout=PROCEDURE_TIMEOUT)
    inertia = number(page.get_by_test_id("identified-inertia").inner_text())
    assert inertia == pytest.approx(rig.plant.total_inertia, rel=0.10)
    ratio = number(page.get_by_test_id("identified-ratio").inner_text())
    assert ratio == pytest.approx(rig.plant.total_inertia / rig.plant.motor_inertia, rel=0.10)
    kp_row = page.get_by_test_id("tuning-gains-kp_speed")
    expect(kp_row).to_contain_text("KPv")
    after = int(kp_row.locator("td").nth(2).inner_text())
    assert int(kp_row.locator("td").nth(1).inner_text()) == before and rig.raw("0x60F9,2") == after
    expect(page.get_by_test_id("verify-speed-plot")).to_have_attribute("data-drawn", re.compile(r"^\d+$"))
    expect(page.get_by_test_id("verify-speed-rise")).to_have_text(re.compile(r"ms$"))
    expect(page.get_by_test_id("verify-speed-overshoot")).to_have_text(re.compile(r"%$"))
    expect(page.get_by_test_id("verify-speed-settling")).to_have_text(re.compile(r"ms$"))
    # measured from the two recorded speed steps (their mean frequency response), not from the tuning formula; this
    # rig's plant is a two-mass axis (anti-resonance near 87 Hz): its loop reaches about 53 Hz of the 75 requested
    # (the simulator's shaft speed says the same), so the page is judged on showing the measurement, the bandwidth
    # itself on rigid plants in tests/services/procedures/test_procedures_plants.py
    shown = page.get_by_test_id("verify-speed-bandwidth")
    row = page.get_by_test_id("verify-speed").locator("tr").filter(has=shown)
    expect(row).to_contain_text(re.compile(r"\([12] of 2 steps\)"))
    expect(shown).to_have_text(re.compile(r"^\d+(\.\d+)? Hz$"))
    expect(page.get_by_test_id("verify-position-plot")).to_have_attribute("data-drawn", re.compile(r"^\d+$"))
    saved = page.get_by_test_id("saved-results").get_by_test_id("saved-row").first
    expect(saved).to_contain_text("auto_tuning")
    screenshot(page, "procedures-tuning")

    page.get_by_test_id("tuning-undo").click()
    expect(page.get_by_test_id("undo-done")).to_be_visible()
    assert rig.raw("0x60F9,2") == before
    kept = httpx.get(f"{rig.url}/api/projects/rig/axes/A/procedures", timeout=15.0).json()
    assert kept[0]["procedure"] == "auto_tuning" and kept[0]["gains"]["after"]["kp_speed"] == after


def test_warning_bit_30_on_the_dashboard_is_remedied_in_one_click(page: Page, rig: Rig) -> None:
    # The motor data keep the commutation auto-phasing found (the drive copies 0x6410,14..16 to 0x3410 when it loads
    # its parameters), then 'save': it survives the reset, the incremental encoder's zero does not.
    for sub in (1, 2, 3):
        rig.write(f"0x6410,{13 + sub}", rig.raw(f"0x3410,{sub}"))
    rig.write("0x1010,1", 0x65766173)
    rig.write("0x205D,0", 2)  # Reset Node = warm reset (as a 24 V power-up): the incremental counter restarts
    response = httpx.post(f"{rig.url}/api/buses/{rig.bus}/nmt", json={"command": "reset-node", "node": 1}, timeout=15.0)
    assert response.is_success, response.text
    deadline = time.monotonic() + 30
    while not phasing_warned(rig) and time.monotonic() < deadline:  # the node boots again
        time.sleep(0.2)
    assert phasing_warned(rig)
    assert (rig.raw("0x3410,1"), rig.raw("0x3410,2")) == (rig.plant.pole_pairs, rig.plant.phase_order)
    axis_page(page, rig, "")
    warning = page.get_by_test_id("phasing-warning")
    expect(warning).to_be_visible(timeout=READ_TIMEOUT)
    remedy = page.get_by_test_id("phasing-remedy")
    arm(page)
    expect(remedy).to_be_enabled()
    remedy.click()
    expect(page.get_by_test_id("phasing-remedy-done")).to_be_visible(timeout=PROCEDURE_TIMEOUT)
    expect(warning).to_have_count(0, timeout=READ_TIMEOUT)
    assert not phasing_warned(rig)


def phasing_warned(rig: Rig) -> bool:
    """The drive reports warning 31 (bit 30) "Motor phasing init not OK"."""
    response = httpx.get(rig.node("/faults"), timeout=15.0)
    return response.is_success and any("motor phasing" in item["name"].lower() for item in response.json()["warnings"])
