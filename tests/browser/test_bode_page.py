"""The Bode page in Chromium against the demo server's simulated XtrapulsPac: a plant measurement of the drive's true
plant (the simulator's commissioned axis, saved by the store as a measurement would be), the predicted closed loop
drawn at once, a KPv slider moved and the predicted bandwidth rising while the drive keeps its gains, then "Write
these gains" and the gains read back from the drive over REST; a saved closed-loop result overlaid and exported."""

from __future__ import annotations

import cmath
import math
import re

import httpx
import pytest
from playwright.sync_api import Page, expect
from tests.support.browser import DemoServer, screenshot

from servostudio.od import builtin_library
from servostudio.services.frequency import store
from servostudio.services.projects import ProjectService
from servostudio.sim.plant import Plant

AXIS, NODE = "Z", 3
PERIOD = 250e-6
STEPS = 40  # arrow-key presses on the KPv slider: ×10^(2·40/400) = ×1.58
SINGLE = 5  # of them timed one by one


def measured_plant(plant: Plant, frequency: float) -> complex:
    """The true rigid plant as a measurement gives it on the simulated drive: 1/(J·s + B) one control period early
    (docs/frequency-response.md §5)."""
    omega = 2 * math.pi * frequency
    return cmath.exp(1j * omega * PERIOD) / complex(plant.viscous_friction, omega * plant.total_inertia)


def measurement(plant: Plant, loop: dict) -> dict:
    points = []
    for number in range(60):
        frequency = 5.0 * (400 / 5.0) ** (number / 59)
        value = measured_plant(plant, frequency)
        points.append({"freq_hz": frequency, "magnitude_db": 20 * math.log10(abs(value)),
                       "phase_deg": math.degrees(cmath.phase(value)), "coherence": 0.99})  # fmt: skip
    return {
        "kind": "frequency_response", "loop": "plant", "node": NODE, "device": "xtrapulspac", "axis": AXIS,
        "time": "2026-12-02T10:00:00Z", "user": "test",
        "excitation": {"type": "multisine", "from_hz": 5, "to_hz": 400, "points": 60},
        "points": points,
        "markers": {"bandwidth_hz": None, "gain_margin_db": None, "phase_margin_deg": None, "resonance_hz": None,
                    "antiresonance_hz": None},
        "plant_fit": {"inertia_kgm2": plant.total_inertia, "viscous_friction_nms_per_rad": plant.viscous_friction},
        "gains": {key: value for key, value in loop.items() if key != "raw"}, "aborted": None,
    }  # fmt: skip


@pytest.fixture(scope="module")
def bode_server(live_server: DemoServer):
    """The demo server with a plant measurement (and a closed-loop one) saved under axis Z; Z's gains put back."""
    path = f"/api/buses/{live_server.bus}/nodes/{NODE}/speed-loop"
    loop = live_server.api("GET", path).json()
    assert live_server.projects_dir is not None
    projects = ProjectService(live_server.projects_dir, builtin_library()).store
    store.save(projects, "demo", AXIS, measurement(Plant.commissioned(), loop), "true plant")
    closed = {**measurement(Plant.commissioned(), loop), "loop": "closed", "time": "2026-12-02T09:00:00Z"}
    store.save(projects, "demo", AXIS, closed, "other set")
    yield live_server, path, loop
    written = {"kp_a_per_rad_s": loop["kp_a_per_rad_s"], "ki_a_per_rad": loop["ki_a_per_rad"]}
    live_server.api("PUT", path, json=written)


def number(page: Page, testid: str, pattern: str = r"([-+0-9.e]+)") -> float:
    text = page.get_by_test_id(testid).inner_text()
    found = re.match(pattern, text)
    assert found, f"{testid}: {text!r}"
    return float(found.group(1))


def single_change(page: Page) -> tuple[float, float, float]:
    """One arrow-key step of the focused slider, waited for until both plots are drawn again: the times the page
    measured (prediction, Bode drawing, step drawing) in ms."""
    counters = [page.get_by_test_id(testid).get_attribute("data-drawn") for testid in ("bode-plot", "bode-step-plot")]
    page.keyboard.press("ArrowRight")
    page.wait_for_function(
        "([bode, step]) => document.querySelector('[data-testid=bode-plot]').dataset.drawn !== bode &&"
        " document.querySelector('[data-testid=bode-step-plot]').dataset.drawn !== step",
        arg=counters,
    )
    draw = [
        float(page.get_by_test_id(testid).get_attribute("data-draw-ms") or "nan")
        for testid in ("bode-plot", "bode-step-plot")
    ]
    return number(page, "whatif-ms"), draw[0], draw[1]


def test_what_if_predicts_then_writes_the_gains(page: Page, bode_server):
    server, path, before = bode_server
    page.goto(f"{server.url}/projects/demo/axes/{AXIS}/bode")
    expect(page.get_by_test_id("bode-plot")).to_have_attribute("data-drawn", re.compile(r"\d+"))
    expect(page.get_by_test_id("whatif-bandwidth")).to_have_text(re.compile(r"\d+(\.\d+)? Hz"))
    drive_bandwidth = number(page, "whatif-bandwidth-drive")
    assert number(page, "whatif-bandwidth") == drive_bandwidth
    expect(page.get_by_test_id("whatif-speed-filter").locator("option")).to_have_text(["0.5 ms", "1 ms", "2 ms"])

    slider = page.get_by_test_id("whatif-kp")
    start = int(slider.input_value())
    slider.focus()
    for _ in range(STEPS - SINGLE):
        page.keyboard.press("ArrowRight")
    timings = [single_change(page) for _ in range(SINGLE)]
    expect(slider).to_have_value(str(start + STEPS))
    predicted = number(page, "whatif-bandwidth")
    assert predicted > 1.3 * drive_bandwidth, (predicted, drive_bandwidth)
    assert number(page, "whatif-bandwidth-drive") == drive_bandwidth
    # The prediction itself is timed by the page; the drawing depends on how loaded the shared machine is, so the
    # fastest of the single changes stands for its cost (contention only adds to it).
    print("what-if per change [ms]: prediction, Bode drawing, step drawing:", timings)
    assert max(prediction for prediction, _, _ in timings) < 50, timings
    assert min(bode + step for _, bode, step in timings) < 50, timings
    expect(page.get_by_test_id("bode-step-plot")).to_have_attribute("data-drawn", re.compile(r"\d+"))
    assert server.api("GET", path).json()["kp_a_per_rad_s"] == before["kp_a_per_rad_s"]  # nothing written yet
    screenshot(page, "bode-what-if")

    page.get_by_test_id("whatif-write").click()
    page.get_by_test_id("confirm").click()
    expect(page.get_by_test_id("bode-written")).to_be_visible()
    after = server.api("GET", path).json()
    wanted = before["kp_a_per_rad_s"] * 10 ** (2 * (start + STEPS) / 400 - 1)
    assert after["kp_a_per_rad_s"] == pytest.approx(wanted, rel=2e-3)
    assert after["ki_a_per_rad"] == pytest.approx(before["ki_a_per_rad"], rel=1e-3)
    expect(page.get_by_test_id("whatif-write")).to_be_disabled()  # the drive now has the what-if gains
    assert number(page, "whatif-bandwidth-drive") == pytest.approx(predicted, rel=1e-3)


def test_saved_sets_overlay_and_export(page: Page, bode_server):
    server, _, _ = bode_server
    page.goto(f"{server.url}/projects/demo/axes/{AXIS}/bode")
    other = page.locator('[data-testid="bode-saved-row"][data-name="other set"]')
    expect(page.get_by_test_id("bode-markers")).to_be_visible()
    other.get_by_test_id("saved-show").check()
    expect(page.get_by_test_id("bode-markers").locator("th", has_text="other set")).to_be_visible()
    overlay = page.get_by_test_id("overlay-html").get_attribute("href")
    document = httpx.get(server.url + overlay, timeout=15.0)
    assert document.status_code == 200 and "other set" in document.text and "true plant" in document.text
    csv = httpx.get(server.url + other.get_by_test_id("saved-csv").get_attribute("href"), timeout=15.0)
    assert csv.text.splitlines()[
        next(i for i, line in enumerate(csv.text.splitlines()) if not line.startswith("#"))
    ] == ("freq_hz,magnitude_db,phase_deg,coherence")
    page.get_by_test_id("bode-view-plant").click()
    expect(page.get_by_test_id("bode-empty")).to_be_hidden()
    screenshot(page, "bode-overlay")


DOWN = 120  # arrow-key presses: KPv × 10^(−2·120/400) = × 0.25, a bandwidth far inside the measured band
MEASURE_TIMEOUT = 120_000  # ms: the demo server's simulator runs in real time on a shared machine


def test_measure_then_what_if_then_write_and_re_measure(page: Page, live_server: DemoServer):
    """Through the page only, on axis Y: arm, measure the plant, lower KPv in the what-if, write it, and the closed
    loop is measured again by itself with the predicted bandwidth beside the re-measured one."""
    path = f"/api/buses/{live_server.bus}/nodes/2/speed-loop"
    before = live_server.api("GET", path).json()
    page.goto(f"{live_server.url}/projects/demo/axes/Y/bode")
    expect(page.get_by_test_id("bode-saved-none")).to_be_visible()
    page.get_by_test_id("control-arm").click()
    expect(page.get_by_test_id("controller-holder")).to_have_text("Armed by this page")
    quick = {
        "from_hz": "10",
        "to_hz": "200",
        "points": "20",
        "periods": "2",
        "base_speed_rad_s": "10",
        "position_window": "20",
    }
    for key, value in quick.items():
        page.get_by_test_id(f"measure-{key}").fill(value)
    page.get_by_test_id("measure-start").click()
    expect(page.get_by_test_id("saved-plant")).to_be_checked(timeout=MEASURE_TIMEOUT)
    expect(page.get_by_test_id("whatif-bandwidth")).to_have_text(re.compile(r"\d+(\.\d+)? Hz"))
    drive_bandwidth = number(page, "whatif-bandwidth-drive")
    page.get_by_test_id("whatif-kp").focus()
    for _ in range(DOWN):
        page.keyboard.press("ArrowLeft")
    expect(page.get_by_test_id("whatif-bandwidth")).not_to_have_text(
        page.get_by_test_id("whatif-bandwidth-drive").inner_text()
    )
    predicted = number(page, "whatif-bandwidth")
    assert predicted < 0.7 * drive_bandwidth, (predicted, drive_bandwidth)
    try:
        page.get_by_test_id("whatif-write").click()
        page.get_by_test_id("confirm").click()
        expect(page.get_by_test_id("bode-written")).to_be_visible()
        assert live_server.api("GET", path).json()["kp_a_per_rad_s"] == pytest.approx(
            before["kp_a_per_rad_s"] * 10 ** (-2 * DOWN / 400), rel=0.02
        )
        expect(page.get_by_test_id("bode-check-measured")).to_have_text(
            re.compile(r"re-measured \d"), timeout=MEASURE_TIMEOUT
        )
        shown = number(page, "bode-check-predicted", r"Predicted bandwidth ([0-9.]+)")
        assert shown == pytest.approx(predicted, rel=0.01)  # what the what-if showed for the written gains
        expect(page.locator('[data-testid="bode-saved-row"]')).to_have_count(2)  # the plant and the re-measured loop
        screenshot(page, "bode-measured")
    finally:
        page.get_by_test_id("control-release").click()
        live_server.api(
            "PUT", path, json={"kp_a_per_rad_s": before["kp_a_per_rad_s"], "ki_a_per_rad": before["ki_a_per_rad"]}
        )
