"""A new simulated encoTRive holds the manual's ramps and speed limits, so a speed ramp move runs out of the box,
and the inertia setting its speed controller is computed from."""

from __future__ import annotations

import pytest
from tests.support.shaft_step import encotrive_bandwidth

from servostudio.sim.drive.encotrive import FACTORY_VALUES
from servostudio.sim.plant import Plant


def test_a_fresh_encotrive_has_no_zero_ramp_or_speed_limit(harness):
    h = harness("encotrive")
    limits = {index: h.read(index) for index in (0x607F, 0x6081, 0x6083, 0x6084, 0x6085, 0x60C5, 0x60C6)}
    assert limits == {
        0x607F: 4400,
        0x6081: 4400,
        0x6083: 4000,
        0x6084: 12000,
        0x6085: 9000,
        0x60C5: 15000,
        0x60C6: 15000,
    }
    assert {index for index, _ in FACTORY_VALUES} <= set(limits)


def test_a_speed_ramp_move_runs_with_the_factory_values(harness):
    h = harness("encotrive")
    h.enable(3)
    h.write(0x60FF, 0, 600)  # rpm, reached in 0.15 s at 4000 rpm/s
    h.run(0.4)
    assert h.read(0x606C) == pytest.approx(600, abs=6)


def test_factory_values_come_back_with_the_other_defaults(harness):
    h = harness("encotrive")
    h.write(0x6083, 0, 1)
    h.store.restore_defaults()
    assert h.read(0x6083) == 4000


def test_the_speed_loop_follows_the_inertia_setting(harness):
    """0x2F02,8 Θi (p. 218): the factory's is the rotor's own inertia; writing a larger one raises the speed loop's
    bandwidth, measured on the true plant's shaft (Θi = J puts the crossover at ωd = 253 rad/s: about 53 Hz)."""
    plant = Plant.from_seed(3)  # load 3.1 × the rotor
    h = harness("encotrive", plant, False)
    assert h.read(0x2F02, 8) == round(plant.motor_inertia / 1e-7)
    true = round(plant.total_inertia / 1e-7)
    bandwidths = [encotrive_bandwidth(plant, raw) for raw in (None, true // 2, true, 2 * true)]
    assert bandwidths == sorted(bandwidths) and bandwidths[0] < 25
    assert bandwidths[2] == pytest.approx(53, rel=0.1)
    assert bandwidths[3] > 1.8 * bandwidths[2]
