"""The frequency response of a drive without a recorder, through synchronous TPDOs answered to the SYNCs that carry the
excitation (docs/frequency-response.md §8), on simulated CD1-ks commissioned for HIDDEN seeded plants and judged
against the plants' true values: the latency of a value from its SYNC to the response, the plant on awkward plants,
the closed loop's bandwidth against a step on the simulator, the bus budget, and the abort at the position window
with everything the run borrowed written back; and the free-running encoTRive (no 0x1006), whose response is
placed in time, on the bench in real time.

Then the source's estimator pieces on signals whose answer is known exactly (no drive): the current monitor's
timing, the held staircase's line, the latency found from the read-back.

The CD1-k gives no torque constant: its plant is per ampere of the current actual value (0x6078, ‰ of the drive's
rating 6510h/4), so the truth it is judged by is Kt/(J·s + B) with the hidden plant's Kt.
"""

from __future__ import annotations

import cmath
import itertools
import math
import threading
import time

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from tests.support.plant_truth import plant_error, step_bandwidth

from servostudio.drive.cia402 import State
from servostudio.drive.control import set_state
from servostudio.drive.rpdo import last_rpdo, read_rpdo
from servostudio.drive.sync import CYCLE_PERIOD
from servostudio.drive.tpdo import read_tpdo, tpdo_slots
from servostudio.services.audit import acting_as
from servostudio.services.cancel import Cancellation, Cancelled
from servostudio.services.frequency import estimate
from servostudio.services.frequency.measure import MODE_PV, SYNC_PERIOD_S, MeasureRequest, check_request
from servostudio.services.frequency.stream import ExcitationStream
from servostudio.services.frequency.timed import WINDOWS
from servostudio.services.frequency.tpdo_source import (
    BusTooSlow,
    NotApplied,
    ResponseStream,
    held_input,
    latency,
    plan_response,
)
from servostudio.services.procedures.run import disable
from servostudio.sim.plant import Plant

CD1K_PER_REV = 65536
#: the simulated CD1-k: the lightest axis for its motor of the rigid seeds (J/Kt smallest: little current, much
#: speed) and a heavy axis on a weak motor (J/Kt largest: much current, little speed)
AWKWARD = (22, 67)
STEEP = 10**9  # ramps the speed loop never sees


def borrowed(drive) -> tuple:
    """What a measurement borrows on the drive: every TPDO, the last RPDO and the communication cycle period."""
    tpdos = tuple(read_tpdo(drive, slot) for slot in tpdo_slots(drive.dictionary))
    return tpdos, read_rpdo(drive, last_rpdo(drive)), drive.read(CYCLE_PERIOD).raw


@pytest.mark.parametrize("seed", AWKWARD)
def test_the_cd1k_s_plant_through_tpdos_follows_the_hidden_plant(frequency_bench, seed):
    plant = Plant.from_seed(seed)
    assert not plant.two_mass
    bench = frequency_bench(plant, device="cd1k")
    before = borrowed(bench.drive())
    result = bench.measure(loop="plant", amplitude_pct=80, base_speed_rad_s=15, periods=4, position_window=40)
    assert result["aborted"] is None
    assert result["excitation"]["source"] == "tpdo" and result["excitation"]["sample_period_us"] == 750.0
    band = [point for point in result["points"] if 4.9 <= point["freq_hz"] <= 200.0]
    assert band[0]["freq_hz"] == pytest.approx(5.0, rel=0.01) and band[-1]["freq_hz"] > 190.0
    per_ampere = 20.0 * math.log10(plant.torque_constant)
    errors = [(db - per_ampere, deg) for db, deg in (plant_error(point, plant) for point in band)]
    assert max(abs(db) for db, _ in errors) < 1.0, errors
    assert max(abs(deg) for _, deg in errors) < 10.0, errors
    assert result["plant_fit"] is None  # per ampere: no J in kg·m² without the torque constant
    assert borrowed(bench.drive()) == before  # TPDOs, RPDO and 0x1006 written back


def test_the_cd1k_s_closed_loop_bandwidth_through_tpdos_agrees_with_a_step(frequency_bench):
    plant = Plant.from_seed(3)
    bench = frequency_bench(plant, device="cd1k")
    result = bench.measure(loop="closed", amplitude_pct=40, base_speed_rad_s=15, periods=4, position_window=40)
    assert result["aborted"] is None and result["excitation"]["source"] == "tpdo"
    low = [point for point in result["points"] if point["freq_hz"] <= 200]
    assert min(point["coherence"] for point in low) > 0.9
    assert abs(low[0]["phase_deg"]) < 2.0  # the one-SYNC latency taken out: no lead or lag at 5 Hz
    expected = step_bandwidth(plant, device="cd1k", per_rev=CD1K_PER_REV)
    assert result["markers"]["bandwidth_hz"] == pytest.approx(expected, rel=0.10)


def test_a_value_sent_before_sync_k_is_applied_at_k_and_moves_the_shaft_from_sample_k_plus_1(frequency_bench):
    """CiA 301: a synchronous RPDO takes effect at the SYNC after its reception; a synchronous TPDO carries what the
    drive has at the SYNC. A velocity step sent before SYNC ``STEP`` is read back at sample ``STEP``; the shaft
    position of that sample is still the old speed's, the next one is not."""
    bench = frequency_bench(Plant.from_seed(3), device="cd1k")
    drive, base, step_at = bench.drive(), 15.0 / (2 * math.pi) * CD1K_PER_REV, 800
    before = borrowed(drive)
    with acting_as(bench.controller()):
        drive.write("modes_of_operation", MODE_PV)
        for name in ("profile_acceleration", "profile_deceleration"):
            drive.write(name, STEEP)
        set_state(drive, State.OPERATION_ENABLED)
        drive.write("target_velocity", round(base))
        stream = ExcitationStream(drive, bench.connection.link, drive.variable("target_velocity"), SYNC_PERIOD_S)
        plan = plan_response(drive, drive.variable("target_velocity"), None, SYNC_PERIOD_S, True)
        response = ResponseStream(plan, drive, bench.connection.link)
        try:
            stream.open(bench.connection.nmt_state(1) == "OPERATIONAL")
            response.open()
            stream.start(lambda k: round(base * (1.5 if k >= step_at else 1.0)), response.answered)
            while response.answered() < step_at + 10:
                assert stream.error is None
                time.sleep(0.01)
            columns = response.columns(step_at - 20, 30)
        finally:
            stream.stop()
            response.close()
            stream.close()
            drive.write("target_velocity", 0)
            time.sleep(0.3)
            disable(drive)
    positions, targets = columns[0], columns[1]
    at = 20  # sample STEP in the columns
    assert targets[at - 1] == round(base) and targets[at] == round(1.5 * base)  # applied at its SYNC, read back there
    increments = [later - earlier for earlier, later in itertools.pairwise(positions)]
    steady = increments[at - 10 : at]  # up to sample STEP: the old speed, 0.75 ms of it per sample
    expected = base * SYNC_PERIOD_S
    assert all(abs(increment - expected) <= 2 for increment in steady), steady
    shown = increments[at - 2 : at + 4]
    assert increments[at] > expected + 3 and increments[at + 1] > increments[at], shown  # STEP + 1: the step taken
    assert borrowed(drive) == before


def test_a_bus_too_slow_for_the_sync_rate_is_refused_before_anything_is_written(frequency_bench):
    bench = frequency_bench(Plant.from_seed(3), device="cd1k")
    drive = bench.drive()
    before = borrowed(drive)
    with pytest.raises(BusTooSlow, match=r"360 bits per SYNC, every 750 µs 96% of 0.5 Mbit/s \(at most 70%\)"):
        check_request(drive, MeasureRequest(loop="plant"), 500_000)
    check_request(drive, MeasureRequest(loop="plant"), 1_000_000)  # 48 %
    assert borrowed(drive) == before


def test_leaving_the_position_window_through_tpdos_quick_stops_and_puts_everything_back(frequency_bench):
    bench = frequency_bench(Plant.from_seed(8), device="cd1k")
    drive = bench.drive()
    before = borrowed(drive)
    result = bench.measure(loop="plant", amplitude_pct=30, base_speed_rad_s=15, periods=6, position_window=0.3)
    assert result["aborted"] is not None and "position window" in result["aborted"], result["aborted"]
    assert result["points"] == [] and result["excitation"]["source"] == "tpdo"
    assert int(drive.read("statusword").raw) & 0x6F != 0x27  # not left enabled
    assert borrowed(drive) == before


def test_a_cancel_through_tpdos_stops_the_axis_and_puts_everything_back(frequency_bench):
    bench = frequency_bench(Plant.from_seed(8), device="cd1k")
    drive = bench.drive()
    before = borrowed(drive)
    cancellation = Cancellation()
    timer = threading.Timer(1.0, cancellation.cancel)  # the stream runs by then (no motion guard in the call)
    timer.start()
    with pytest.raises(Cancelled):
        bench.measure(cancellation, loop="closed", base_speed_rad_s=15, periods=8, position_window=40)
    timer.join()
    assert int(drive.read("statusword").raw) & 0x6F != 0x27
    assert borrowed(drive) == before


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 3), st.integers(1, 190), st.floats(0.0, 2 * math.pi))
def test_a_current_taken_every_millisecond_has_the_lines_of_one_taken_at_every_sync(first, harmonic, phase):
    """0x6078 holds the current of the control period before each 1-ms update (every 4th period); sampled at every
    SYNC (3 periods, sample 0 at period ``first``) its lines are those of the current at the SYNC instants."""
    block = 532

    def current(period: int) -> float:
        return math.cos(2 * math.pi * harmonic * period / (3 * block) + phase)

    periods = [first + 3 * k for k in range(2 * block)]
    monitored = [current(4 * (period // 4) - 1) for period in periods]
    lines = estimate.monitored_lines(monitored, [harmonic], block, 3, 4)
    ideal = estimate.block_lines([current(period) for period in periods], [harmonic], block)
    assert len(lines) == 2
    for got, want in zip(lines, ideal, strict=True):
        assert abs(got[0] - want[0]) < 1e-6 * abs(want[0])


@pytest.mark.parametrize("delay", [0, 1])
def test_the_held_input_is_the_line_of_the_staircase_the_drive_held(delay):
    """Value k held from sample k to k + 1 (shown ``delay`` samples later): its line is the staircase's, integrated
    finely (midpoint rule) — a sample's lead and the hold's droop taken out exactly."""
    block, harmonics, fine = 64, [1, 5, 17, 30], 256
    values = [math.sin(0.3 * k) + 0.5 * math.cos(1.7 * k) for k in range(block)]
    shown = [values[(k - delay) % block] for k in range(block)]
    held = held_input(estimate.block_lines(shown, harmonics, block), harmonics, block, delay)[0]
    for line, harmonic in zip(held, harmonics, strict=True):
        turn = -2j * math.pi * harmonic / block
        staircase = sum(
            values[k] * cmath.exp(turn * (k + (r + 0.5) / fine)) / fine for k in range(block) for r in range(fine)
        )
        assert abs(line - staircase) < 1e-4 * abs(staircase)


def test_the_latency_is_found_from_the_read_back_and_a_read_back_not_the_excitation_fails():
    def sent(k: int) -> int:
        return k * 37 % 101

    assert latency([float(sent(100 + k)) for k in range(200)], sent, 100) == 0
    assert latency([float(sent(99 + k)) for k in range(200)], sent, 100) == 1  # answered before it applied
    with pytest.raises(NotApplied, match="not the excitation sent"):
        latency([float(sent(100 + k // 2)) for k in range(200)], sent, 100)  # values a SYNC late half the time


def _errors(result: dict, plant: Plant, up_to_hz: float) -> tuple[float, float]:
    """The largest |dB| and |°| of the measured plant against its true 1/(J·s + B) up to ``up_to_hz``."""
    errors = [plant_error(point, plant) for point in result["points"] if point["freq_hz"] <= up_to_hz]
    return max(abs(db) for db, _ in errors), max(abs(deg) for _, deg in errors)


def test_the_free_running_encotrive_s_plant_is_measured_in_time(frequency_bench):
    """The encoTRive has neither a recorder nor 0x1006: it takes each SYNC when it comes. Its excitation follows the
    drive's time and its answers are placed at their own time stamps (docs/frequency-response.md §8), so the
    hidden plant comes out within 1.5 dB and 10° to 100 Hz, 3 dB and 20° to 200 Hz, on the bench in real time."""
    plant = Plant.from_seed(22)
    bench = frequency_bench(plant, speed=1.0, device="encotrive")
    before = tuple(read_tpdo(bench.drive(), slot) for slot in tpdo_slots(bench.drive().dictionary))
    result = bench.measure(loop="plant", amplitude_pct=80, base_speed_rad_s=15, to_hz=200, position_window=200)
    assert result["aborted"] is None and result["excitation"]["source"] == "tpdo"
    assert result["excitation"]["periods"] == WINDOWS
    low, high = _errors(result, plant, 100.5), _errors(result, plant, 200.5)
    assert low[0] < 1.5 and low[1] < 10.0, low
    assert high[0] < 3.0 and high[1] < 20.0, high
    assert tuple(read_tpdo(bench.drive(), slot) for slot in tpdo_slots(bench.drive().dictionary)) == before


def test_the_free_running_encotrive_s_closed_loop_bandwidth_agrees_with_a_step(frequency_bench):
    plant = Plant.from_seed(5)
    bench = frequency_bench(plant, speed=1.0, device="encotrive")
    result = bench.measure(loop="closed", amplitude_pct=80, base_speed_rad_s=15, to_hz=300, position_window=200)
    assert result["aborted"] is None
    expected = step_bandwidth(plant, device="encotrive", per_rev=60)  # the encoTRive's speeds are in rpm
    assert result["markers"]["bandwidth_hz"] == pytest.approx(expected, rel=0.10)
