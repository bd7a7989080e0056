"""The frequency response measured on simulated XtrapulsPacs commissioned for HIDDEN seeded plants, judged against
the plants' true values (never against the tool's own formulas): the rigid plant's 1/(J·s + B), a two-mass
plant's resonance, the closed loop's bandwidth from a step on the simulator, and an abort at the position window.

Phase: the simulated mechanics take the current of a control period's end for the whole period (semi-implicit
integration, sim/drive/physics.py), which leads 1/(J·s + B) by one control period (250 µs: 18° at 200 Hz); the
comparison removes that known sample delay (docs/frequency-response.md §5).
"""

from __future__ import annotations

import math
from dataclasses import replace

import pytest
from tests.support.plant_truth import TWO_PI, plant_error, step_bandwidth

from servostudio.services.frequency import measure
from servostudio.services.frequency.stream import ExcitationStream
from servostudio.sim.plant import Plant


@pytest.mark.parametrize("seed", [3, 21])
def test_the_measured_plant_follows_the_hidden_rigid_plant(frequency_bench, seed):
    plant = Plant.from_seed(seed)
    assert not plant.two_mass
    bench = frequency_bench(plant)
    result = bench.measure(loop="plant", amplitude_pct=100, base_speed_rad_s=15, periods=4, position_window=40)
    assert result["aborted"] is None
    band = [point for point in result["points"] if 4.9 <= point["freq_hz"] <= 200.0]
    assert band[0]["freq_hz"] == pytest.approx(5.0, rel=0.01) and band[-1]["freq_hz"] > 190.0
    errors = [plant_error(point, plant) for point in band]
    assert max(abs(db) for db, _ in errors) < 1.0, errors
    assert max(abs(deg) for _, deg in errors) < 10.0, errors
    assert result["plant_fit"]["inertia_kgm2"] == pytest.approx(plant.total_inertia, rel=0.10)
    # rigid: no resonance and no anti-resonance anywhere in the sweep — the noise a loaded host adds near its top
    # (γ² 0.84–0.96 above 250 Hz) makes no marker (docs/frequency-response.md §6)
    found = result["markers"]
    assert found["resonance_hz"] is None and found["antiresonance_hz"] is None, found
    assert bench.drive().read("torque_offset").raw == 0  # put back


def two_mass(seed: int, ratio: float, resonance_hz: float) -> Plant:
    """The load ``ratio`` × the motor inertia on a coupling resonating (motor against load) at ``resonance_hz``."""
    plant = Plant.from_seed(seed)
    load = plant.motor_inertia * ratio
    reduced = plant.motor_inertia * load / (plant.motor_inertia + load)
    stiffness = reduced * (TWO_PI * resonance_hz) ** 2
    return replace(
        plant,
        load_inertia=load,
        coupling_stiffness=stiffness,
        coupling_damping=0.05 * 2 * math.sqrt(stiffness * reduced),
    )


def test_a_two_mass_plant_s_resonance_is_found(frequency_bench):
    plant = two_mass(44, 2.0, 140.0)
    reduced = plant.motor_inertia * plant.load_inertia / plant.total_inertia
    true_hz = math.sqrt(plant.coupling_stiffness / reduced) / TWO_PI
    bench = frequency_bench(plant)
    result = bench.measure(
        loop="plant", amplitude_pct=100, base_speed_rad_s=15, periods=4, points=100, position_window=40
    )
    assert result["aborted"] is None
    assert result["markers"]["resonance_hz"] == pytest.approx(true_hz, rel=0.05), result["markers"]
    assert result["markers"]["antiresonance_hz"] == pytest.approx(
        math.sqrt(plant.coupling_stiffness / plant.load_inertia) / TWO_PI, rel=0.08
    )


def test_the_closed_loop_bandwidth_agrees_with_a_step_on_the_simulator(frequency_bench):
    plant = Plant.from_seed(3)
    bench = frequency_bench(plant)
    result = bench.measure(loop="closed", amplitude_pct=40, base_speed_rad_s=15, periods=4, position_window=40)
    assert result["aborted"] is None
    assert min(point["coherence"] for point in result["points"] if point["freq_hz"] <= 200) > 0.9
    assert result["markers"]["bandwidth_hz"] == pytest.approx(step_bandwidth(plant), rel=0.10)
    assert result["markers"]["phase_margin_deg"] is not None and 20 < result["markers"]["phase_margin_deg"] < 90


def test_leaving_the_position_window_quick_stops_and_aborts(frequency_bench):
    bench = frequency_bench(Plant.from_seed(8))
    mapping_before = bench.drive().read((0x1603, 0)).raw
    result = bench.measure(loop="plant", amplitude_pct=30, base_speed_rad_s=15, periods=6, position_window=0.3)
    assert result["aborted"] is not None and "position window" in result["aborted"], result["aborted"]
    assert result["points"] == [] and result["plant_fit"] is None
    status = int(bench.drive().read("statusword").raw)
    assert status & 0x6F != 0x27  # not left enabled
    assert bench.drive().read((0x1603, 0)).raw == mapping_before  # the borrowed RPDO is back


def test_a_recording_during_which_the_syncs_stalled_is_taken_again(frequency_bench, monkeypatch):
    """A host that held the SYNCs back (here: the stream says so of the first recording) costs a recording, not the
    result: a drive locked to the SYNC loses it, and that recording's excitation is not periodic."""
    plant = Plant.from_seed(3)
    bench = frequency_bench(plant)
    recordings, stalls = [], iter([True])
    real_recording = measure._recording

    def counted(*args):
        recordings.append(real_recording(*args))
        return recordings[-1]

    monkeypatch.setattr(measure, "_recording", counted)
    monkeypatch.setattr(ExcitationStream, "stalled", lambda self, first, last, longest: next(stalls, False))
    result = bench.measure(loop="plant", amplitude_pct=100, base_speed_rad_s=15, periods=2, position_window=40)
    assert result["aborted"] is None and result["excitation"]["periods"] == 2
    assert len(recordings) == 2  # the first one thrown away
    errors = [plant_error(point, plant) for point in result["points"] if 4.9 <= point["freq_hz"] <= 200.0]
    assert max(abs(db) for db, _ in errors) < 1.5, errors
