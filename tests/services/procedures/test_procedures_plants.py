"""End to end on hidden seeded plants through the procedure service, as a user commissions an uncommissioned drive:
motor data from the datasheet → current-loop calculation → auto-phasing → auto-tuning; judged against the plant's
true values (never against the tool's own formula).

The identification itself is the simulated drive's (docs/control-loops.md §4), read back from the identified-plant
object 0x3428; the tool shapes, checks and verifies it.
"""

from __future__ import annotations

import pytest
from tests.support.procedure_bench import commission, datasheet

from servostudio.services.audit import acting_as
from servostudio.services.procedures import ProcedureRequest
from servostudio.services.procedures.commutation import verify_commutation

SEEDS = [101, 202, 303]
TWO_DEGREES = 65536 * 2 / 360


def offset_error(found: int, true: int) -> int:
    difference = (found - true) % 65536
    return min(difference, 65536 - difference)


@pytest.mark.parametrize("seed", SEEDS)
def test_an_uncommissioned_drive_is_commissioned_from_its_datasheet(bench_factory, seed):
    bench = bench_factory(seed=seed)
    plant, current, phasing, tuning = commission(bench)
    assert current["status"] == "done"
    assert current["gains"]["after"]["kp_current_q"] > 0
    assert current["limits"]["after"]["rated_current"] == round(min(plant.stall_current * 1000, 1e9))
    assert phasing["status"] == "done"
    assert phasing["pole_pairs"] == plant.pole_pairs
    assert phasing["phase_order"] == plant.phase_order
    assert offset_error(int(phasing["sensor_offset"]), plant.sensor_offset) <= TWO_DEGREES
    assert phasing["verification"]["passed"] is True, phasing["verification"]
    assert tuning["status"] == "done"
    assert tuning["gains"]["after"] != tuning["gains"]["before"]
    identified = tuning["identified"]
    assert identified["inertia_kgm2"] == pytest.approx(plant.total_inertia, rel=0.10), identified
    assert identified["viscous_friction_nms_per_rad"] == pytest.approx(plant.viscous_friction, rel=0.25), identified
    assert identified["inertia_ratio"] == pytest.approx(plant.total_inertia / plant.motor_inertia, rel=0.12)
    speed, position = tuning["verification"]["speed_step"], tuning["verification"]["position_step"]
    assert speed["rise_time_s"] > 0 and speed["settling_time_s"] is not None  # a recorded step that settles
    assert position["overshoot_pct"] < 2.0  # minimum overshoot: the position does not pass the target


@pytest.mark.parametrize("seed", [101, 505])
def test_the_measured_speed_loop_bandwidth_is_the_requested_one(bench_factory, seed):
    """The −3 dB bandwidth the verification measures from its recorded speed steps (the mean frequency response of
    two steps, one each way) is the requested one, in either position-loop mode."""
    bench = bench_factory(seed=seed)
    *_, first = commission(bench, 50)
    steps = {50: first["verification"]["speed_step"]}
    for bandwidth in (75, 100):
        tuning = bench.run("auto_tuning", ProcedureRequest({"bandwidth": bandwidth}))
        steps[bandwidth] = tuning["verification"]["speed_step"]
    measured = {bandwidth: step["bandwidth_hz"] for bandwidth, step in steps.items()}
    assert all(value is not None for value in measured.values()), steps
    for bandwidth, value in measured.items():
        assert value == pytest.approx(bandwidth, rel=0.20), measured
        assert len(steps[bandwidth]["bandwidth_steps_hz"]) == 2  # averaged over the repeated steps


def test_a_two_mass_plant_with_the_anti_resonance_filter_is_stable(bench_factory):
    bench = bench_factory(seed=9)  # resonance at 216 Hz, load 4.1 x the motor's inertia
    assert bench.plant().two_mass
    *_, tuning = commission(bench, 75, "anti-resonance")
    assert tuning["gains"]["after"]["current_filter_1"] > 0  # the anti-resonance filter is on
    speed = tuning["verification"]["speed_step"]
    assert speed["settling_time_s"] is not None and speed["overshoot_pct"] < 30.0
    response, reference = speed["capture"]["response"], speed["capture"]["reference"]
    tail = response[-200:]  # the last 50 ms: no sustained oscillation
    assert (max(tail) - min(tail)) < 0.15 * abs(reference[-1])
    assert tuning["verification"]["position_step"]["overshoot_pct"] < 2.0


def test_the_commutation_check_measures_a_wrong_offset(bench_factory):
    """A sensor offset 30° electrical off the plant's true one (entered by hand): the check measures the error from
    three torque pulses and fails the commutation (cos 30° = 0.87 < 0.98)."""
    bench = bench_factory(seed=202)
    plant = bench.plant()
    datasheet(bench, plant)
    bench.run("current_loop", ProcedureRequest({"inductance_mh": round(plant.inductance * 1e4) / 10}))
    machine = bench.machine()
    for key, value in (("0x3410,1", plant.pole_pairs), ("0x3410,2", plant.phase_order)):
        machine.write(key, value)
    machine.write("0x3410,3", (plant.sensor_offset + 65536 * 30 // 360) % 65536)
    bench.pace(2.0)
    with acting_as(bench.controller()):
        checked = verify_commutation(bench.drive())
    assert checked["passed"] is False
    assert abs(checked["error_deg"]) == pytest.approx(30.0, abs=2.0)
    assert machine.read("0x3410,3").raw == (plant.sensor_offset + 65536 * 30 // 360) % 65536  # put back
