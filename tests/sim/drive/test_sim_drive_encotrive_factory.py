"""A new simulated encoTRive holds the manual's ramps and speed limits, so a speed ramp move runs out of the box."""

from __future__ import annotations

import pytest

from servostudio.sim.drive.encotrive import FACTORY_VALUES


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
