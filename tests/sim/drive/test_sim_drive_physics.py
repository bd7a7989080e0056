"""Physics seen through the drive's objects: acceleration at a current limit, commutation errors."""

from __future__ import annotations

import math
from dataclasses import replace

import pytest

from servostudio.sim.clock import CONTROL_PERIOD
from servostudio.sim.drive.physics import AxisPhysics
from servostudio.sim.plant import PHASE_120, Plant

USER_PER_REV = 4096


def velocity_rad(h) -> float:
    return h.read(0x606C) / USER_PER_REV * 2 * math.pi


def free_plant(**changes) -> Plant:
    """The commissioned axis without switches/stops in the way."""
    base = dict(
        negative_limit_switch=None,
        positive_limit_switch=None,
        negative_hard_stop=None,
        positive_hard_stop=None,
        home_switch=None,
    )
    base.update(changes)
    return replace(Plant.commissioned(), **base)


def test_pv_acceleration_at_the_current_limit_matches_the_hidden_plant(harness):
    plant = free_plant()
    h = harness(plant=plant)
    h.write(0x6073, 0, 500)  # max current = 50 % of the rated 3 A
    h.write(0x6083, 0, 0xFFFFFFFF // 2)  # profile acceleration far above what the current allows
    h.enable(3)
    h.write(0x60FF, 0, USER_PER_REV * 60)  # 60 rev/s: not reached within the measurement
    h.run(0.02)
    v1 = velocity_rad(h)
    h.run(0.08)
    v2 = velocity_rad(h)
    measured = (v2 - v1) / 0.08
    current = 0.5 * plant.stall_current
    mean_speed = (v1 + v2) / 2
    expected = (plant.torque_constant * current - plant.coulomb_friction - plant.viscous_friction * mean_speed) / (
        plant.total_inertia
    )
    assert measured == pytest.approx(expected, rel=0.05)


def accelerate_in_torque_mode(h, permille: int = 500, seconds: float = 0.02) -> float:
    """PT mode from standstill: mean acceleration (rad/s²) over `seconds`."""
    h.write(0x6087, 0, 10_000_000)  # torque slope: a step
    h.enable(4)
    h.write(0x6071, 0, permille)
    start = h.drive.physics.omega_motor
    h.run(seconds)
    return (h.drive.physics.omega_motor - start) / seconds


def aligned_plant(**changes) -> Plant:
    """Start where the true electrical angle is 0, so a mirrored phase order gives exactly −torque."""
    plant = free_plant(**changes)
    turns = (-plant.sensor_offset / 65536.0) / plant.pole_pairs
    return replace(plant, initial_position=turns)


def test_wrong_commutation_offset_reduces_torque_by_its_cosine(harness):
    correct = harness(plant=aligned_plant())
    reference = accelerate_in_torque_mode(correct)
    wrong = harness(plant=aligned_plant())
    error_turns = 60 / 360  # 60° electrical
    wrong.write(0x3410, 3, (Plant.commissioned().sensor_offset + round(error_turns * 65536)) % 65536)
    reduced = accelerate_in_torque_mode(wrong)
    assert reference > 0
    friction = Plant.commissioned().coulomb_friction / Plant.commissioned().total_inertia
    assert reduced + friction == pytest.approx((reference + friction) * math.cos(math.radians(60)), rel=0.05)


def test_wrong_phase_order_reverses_the_torque(harness):
    correct = harness(plant=aligned_plant())
    reference = accelerate_in_torque_mode(correct, seconds=0.005)
    swapped = harness(plant=aligned_plant())
    swapped.write(0x3410, 2, PHASE_120)
    reversed_ = accelerate_in_torque_mode(swapped, seconds=0.005)
    assert reference > 0 > reversed_
    # dry friction opposes both, and the mirrored field loses alignment as the rotor turns: within 15 %
    assert reversed_ == pytest.approx(-reference, rel=0.15)


def test_encoder_counts_are_quantised():
    plant = free_plant(encoder_counts=1024, initial_position=0.0)
    physics = AxisPhysics(plant, CONTROL_PERIOD)
    physics.theta_motor = 2 * math.pi * (3.5 / 1024 + 0.0001)
    assert physics.sensor_counts() == 3


def test_gravity_pulls_an_unpowered_axis_and_a_brake_holds_it():
    plant = free_plant(gravity_torque=0.5, has_brake=True, brake_torque=2.0)
    physics = AxisPhysics(plant, CONTROL_PERIOD)
    for _ in range(400):
        physics.step(0.0, 0.0, 0.0, 1)
    assert physics.omega_motor == 0.0  # brake engaged at power-up
    physics.brake_engaged = False
    for _ in range(400):
        physics.step(0.0, 0.0, 0.0, 1)
    expected = -(0.5 - plant.coulomb_friction) / plant.total_inertia * 0.1
    assert physics.omega_motor == pytest.approx(expected, rel=0.05)


def test_two_mass_coupling_rings_at_its_resonance():
    plant = free_plant(
        load_inertia=2e-4, coupling_stiffness=200.0, coupling_damping=0.0, coulomb_friction=0.0, viscous_friction=0.0
    )
    physics = AxisPhysics(plant, CONTROL_PERIOD)
    physics.theta_motor += 0.01  # twist the coupling
    crossings = 0
    previous = physics.theta_motor - physics.theta_load
    for _ in range(4000):
        physics.step(0.0, 0.0, 0.0, 1)
        twist = physics.theta_motor - physics.theta_load
        crossings += (twist > 0) != (previous > 0)
        previous = twist
    reduced = plant.motor_inertia * plant.load_inertia / (plant.motor_inertia + plant.load_inertia)
    frequency = math.sqrt(plant.coupling_stiffness / reduced) / (2 * math.pi)
    assert crossings / 2 == pytest.approx(frequency, rel=0.05)


def test_dc_bus_rises_when_braking_and_the_chopper_limits_it(harness):
    plant = free_plant(dc_bus_capacitance=100e-6)
    h = harness(plant=plant)
    h.write(0x6083, 0, USER_PER_REV * 400)
    h.write(0x6084, 0, USER_PER_REV * 400)
    h.enable(3)
    h.write(0x60FF, 0, USER_PER_REV * 60)
    h.run(0.3)
    h.write(0x60FF, 0, 0)
    peak = 0.0
    for _ in range(60):
        h.run(0.0025)
        peak = max(peak, h.drive.physics.dc_bus)
    assert peak > plant.dc_bus_voltage + 10
    assert peak < plant.overvoltage
