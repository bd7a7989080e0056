"""Procedures started by signatures (docs/decisions.md §4): auto-phasing, motor phasing, 'calc', auto-tuning;
status read-back, busy bit, abort, failure with error 64; 0x6410 side effects."""

from __future__ import annotations

import math
from dataclasses import replace

import pytest

from servostudio.sim.drive import gains
from servostudio.sim.drive.procedures import signature
from servostudio.sim.plant import FEEDBACK_ENCODER, PHASE_120, Plant

APHA, MCAL, CALC, ATUN = (signature(s) for s in ("apha", "mcal", "calc", "atun"))
BUSY = 1 << 15


def prepare_uncommissioned(harness, plant: Plant):
    """What a user does first: motor currents and inductance into 0x6410, then 'calc'."""
    h = harness(plant=plant, commissioned=False)
    h.write(0x6410, 9, round(plant.stall_current * 1000))
    h.write(0x6410, 10, round(plant.peak_current * 1000))
    h.write(0x6410, 13, round(plant.inductance * 1e4))
    h.write(0x3411, 0, CALC)
    return h


def offset_error(identified: int, true: int) -> int:
    difference = (identified - true) % 65536
    return min(difference, 65536 - difference)


@pytest.mark.parametrize("seed", [11, 13])
def test_auto_phasing_identifies_the_hidden_motor(harness, seed):
    plant = Plant.from_seed(seed)
    h = prepare_uncommissioned(harness, plant)
    assert h.read(0x3413) == 0  # never executed
    h.write(0x3413, 0, APHA)
    h.run(0.001)
    assert h.read(0x3413) == 2
    assert h.status & BUSY
    h.run_until(lambda: h.read(0x3413) != 2, 20.0, step=0.05)
    assert h.read(0x3413) == 5
    assert not h.status & BUSY
    assert h.read(0x3410, 1) == plant.pole_pairs
    assert h.read(0x3410, 2) == plant.phase_order
    assert offset_error(h.read(0x3410, 3), plant.sensor_offset) < 65536 * 2 / 360  # within 2° electrical


def test_phased_motor_then_runs(harness):
    plant = replace(Plant.from_seed(21), home_switch=None)
    h = prepare_uncommissioned(harness, plant)
    h.write(0x3413, 0, APHA)
    h.run_until(lambda: h.read(0x3413) == 5, 20.0, step=0.05)
    tuned = gains.tuned_gains(plant.total_inertia, plant.torque_constant, 50.0)
    h.write(0x60F9, 2, tuned.kpv)
    h.write(0x60F9, 3, tuned.kiv)
    h.write(0x60F9, 8, tuned.kjv)
    h.write(0x6083, 0, 4096 * 50)
    h.enable(3)
    h.write(0x60FF, 0, 4096 * 2)
    h.run(0.5)
    assert h.read(0x606C) == pytest.approx(4096 * 2, rel=0.05)


def test_procedure_status_semantics(harness):
    plant = Plant.from_seed(5)
    h = prepare_uncommissioned(harness, plant)
    h.write(0x3413, 0, 0x12345678)  # not the signature: ignored
    h.run(0.01)
    assert h.read(0x3413) == 0
    h.write(0x3413, 0, APHA)
    h.run(0.2)
    h.write(0x3413, 0, 0)  # abort
    h.run(0.001)
    assert h.read(0x3413) == 3
    assert not h.status & BUSY
    h.control(0x06)
    h.write(0x3413, 0, APHA)  # Ready To Switch On is still a disabled state: it starts again
    assert h.read(0x3413) == 2
    h.write(0x3413, 0, 0)
    assert h.read(0x3413) == 3


def test_procedure_cannot_execute_while_enabled(harness):
    h = harness()
    h.enable(3)
    h.write(0x3413, 0, APHA)
    assert h.read(0x3413) == 1


def test_procedure_fails_with_error_64_on_an_active_limit_switch(harness):
    plant = replace(Plant.commissioned(), negative_limit_switch=-20.0, initial_position=-20.5, negative_hard_stop=-21.0)
    h = harness(plant=plant)
    h.run(0.001)
    h.write(0x3413, 0, APHA)
    h.run(0.001)
    assert h.read(0x3413) == 4
    assert h.read(0x3022, 2) == 1 << 31
    assert h.events.emergencies[-1][:2] == (0xFFA2, 64)


def test_auto_phasing_fails_when_the_shaft_is_blocked(harness):
    plant = replace(Plant.commissioned(), has_brake=True, brake_torque=50.0)
    h = harness(plant=plant)
    h.write(0x3413, 0, APHA)
    h.run_until(lambda: h.read(0x3413) != 2, 30.0, step=0.1)
    assert h.read(0x3413) == 4
    assert h.read(0x3022, 2) == 1 << 31


def test_incremental_encoder_needs_motor_phasing_before_enable(harness):
    plant = replace(Plant.commissioned(), feedback=FEEDBACK_ENCODER, encoder_counts=8192)
    h = prepare_uncommissioned(harness, plant)
    for sub, value in ((1, plant.pole_pairs), (2, plant.phase_order)):
        h.store.set(0x3410, sub, value)  # known from a previous auto-phasing (saved parameters)
    h.drive.phasing_valid = False
    h.run(0.01)
    assert h.read(0x3024) & (1 << 30)  # motor phasing init not OK
    h.control(0x06)
    h.control(0x07)
    h.control(0x0F)
    assert h.status & 0x6F == 0x23  # enable refused: stays switched on
    h.control(0x06)
    h.write(0x3414, 0, MCAL)
    h.run_until(lambda: h.read(0x3414) != 2, 10.0, step=0.05)
    assert h.read(0x3414) == 5
    h.run(0.01)
    assert not h.read(0x3024) & (1 << 30)
    # the offset makes the drive's angle equal to the true one for this power-up's counter
    physics = h.drive.physics
    drive_angle = (
        2 * math.pi * (plant.pole_pairs * physics.sensor_counts() / physics.counts_per_turn + h.read(0x3410, 3) / 65536)
    )
    error = (drive_angle - physics.true_electrical_angle() + math.pi) % (2 * math.pi) - math.pi
    assert abs(error) < math.radians(3)


def test_calc_sets_the_current_loop_from_the_inductance(harness):
    h = harness(commissioned=False)
    h.write(0x6410, 13, 80)  # 8 mH phase to phase
    assert h.read(0x340F) == 80
    h.write(0x6410, 9, 2500)
    h.write(0x6410, 10, 7500)
    h.write(0x3411, 0, CALC)
    assert h.read(0x3411) == 5
    omega = 2 * math.pi * gains.CURRENT_BANDWIDTH_HZ[0]
    assert h.read(0x60F6, 2) == round(0.004 * omega / gains.CURRENT_KP_UNIT)
    assert h.read(0x60F6, 3) == round(0.004 * omega * omega / 4 / gains.CURRENT_KI_UNIT)
    assert h.read(0x6075) == 2500
    assert h.read(0x6073) == 3000


def test_motor_data_side_effects(harness):
    h = harness(commissioned=False)
    h.write(0x6410, 14, 5)
    h.write(0x6410, 15, PHASE_120)
    h.write(0x6410, 16, 1234)
    h.write(0x6410, 7, 3500)
    assert [h.read(0x3410, s) for s in (1, 2, 3)] == [5, PHASE_120, 1234]
    assert h.read(0x6080) == 3500
    h.write(0x6410, 6, 0x0100)
    if (0x6402, 0) in h.store:
        assert h.read(0x6402) == 0x0100


def test_auto_tuning_identifies_inertia_and_writes_the_gains(harness):
    plant = replace(Plant.commissioned(), home_switch=None)
    h = harness(plant=plant)
    h.write(0x3425, 1, 2)  # 100 Hz
    h.write(0x3425, 4, 0)  # minimum following error
    h.write(0x6060, 0, 1)
    h.write(0x3426, 0, ATUN)
    h.run(0.001)
    assert h.read(0x3426) == 2 and h.status & BUSY
    h.run_until(lambda: h.read(0x3426) != 2, 10.0, step=0.05)
    assert h.read(0x3426) == 5
    expected = gains.tuned_gains(plant.total_inertia, plant.torque_constant, 100.0)
    assert h.read(0x60F9, 8) == expected.kjv
    assert h.read(0x60F9, 2) == pytest.approx(expected.kpv, rel=0.1)
    assert h.read(0x60FB, 3) == gains.KFP_FULL
    assert h.read(0x60FB, 4) == pytest.approx(expected.kav, rel=0.1)
    assert h.read(0x60FB, 2) == expected.kpp
    h.enable(1)  # the tuned axis moves
    h.write(0x6081, 0, 4096 * 10)
    h.write(0x6083, 0, 4096 * 100)
    h.write(0x6084, 0, 4096 * 100)
    start = h.read(0x6064)
    h.write(0x607A, 0, start + 4096 * 3)
    h.control(0x1F)
    h.run(1.0)
    assert abs(h.read(0x6064) - (start + 4096 * 3)) < 10


def test_auto_tuning_in_profile_velocity_leaves_position_gains_zero(harness):
    h = harness(plant=replace(Plant.commissioned(), home_switch=None))
    h.write(0x6060, 0, 3)
    h.write(0x3426, 0, ATUN)
    h.run_until(lambda: h.read(0x3426) != 2, 10.0, step=0.05)
    assert h.read(0x3426) == 5
    assert h.read(0x60FB, 2) == 0
    assert h.read(0x60FB, 3) == 0


def test_commissioned_encoder_axis_still_needs_motor_phasing_after_power_up(harness):
    plant = replace(Plant.commissioned(), feedback=FEEDBACK_ENCODER, encoder_counts=8192, initial_position=0.37)
    h = harness(plant=plant)
    h.run(0.01)
    assert h.read(0x3024) & (1 << 30)
    h.write(0x3414, 0, MCAL)
    h.run_until(lambda: h.read(0x3414) != 2, 10.0, step=0.05)
    assert h.read(0x3414) == 5
    h.enable(3)
    h.write(0x6083, 0, 4096 * 50)
    h.write(0x60FF, 0, 4096 * 2)
    h.run(0.3)
    assert h.read(0x606C) == pytest.approx(4096 * 2, rel=0.05)
