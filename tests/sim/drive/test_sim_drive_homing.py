"""Homing methods against the simulated switches, index pulse and hard stops of a compact axis.

Geometry (motor turns): limit switches at −2 / +2, hard stops at −2.5 / +2.5, home cam 0.5..1.2, index pulse
at every k + 0.3, start at 0. After homing, 0x6064 reads the home offset 0x607C at the reference.
"""

from __future__ import annotations

from dataclasses import replace

import pytest

from servostudio.sim.plant import Plant

REV = 4096
HOME_OFFSET = 1000

PLANT = replace(
    Plant.commissioned(),
    negative_limit_switch=-2.0,
    positive_limit_switch=2.0,
    negative_hard_stop=-2.5,
    positive_hard_stop=2.5,
    home_switch=(0.5, 1.2),
    index_position=0.3,
    initial_position=0.0,
)

EXPECTED_REFERENCE = {
    1: -1.7,
    2: 1.3,
    17: -2.0,
    18: 2.0,
    3: 0.3,
    4: 1.3,
    5: 1.3,
    6: 0.3,
    7: 0.3,
    8: 1.3,
    9: 0.3,
    10: 1.3,
    11: 1.3,
    12: 0.3,
    13: 1.3,
    14: 0.3,
    19: 0.5,
    20: 0.5,
    21: 1.2,
    22: 1.2,
    23: 0.5,
    24: 0.5,
    25: 1.2,
    26: 1.2,
    27: 1.2,
    28: 1.2,
    29: 0.5,
    30: 0.5,
    33: -0.7,
    34: 0.3,
    35: 0.0,
    -1: -1.7,
    -2: 2.3,
    -3: -2.5,
    -4: 2.5,
}
INDEX_METHODS = frozenset(range(1, 15)) | {33, 34, -1, -2}
EDGE_TOLERANCE = 8  # one control period at the slow speed plus quantisation
INDEX_TOLERANCE = 2


def run_homing(harness, method: int, plant: Plant = PLANT, end_on_home: int = 1):
    h = harness(plant=plant)
    h.write(0x6098, 0, method)
    h.write(0x6099, 1, REV * 8)
    h.write(0x6099, 2, REV * 1)
    h.write(0x609A, 0, REV * 200)
    h.write(0x607C, 0, HOME_OFFSET)
    h.write(0x309D, 0, end_on_home)
    h.enable(6)
    h.control(0x1F)
    h.run_until(lambda: h.status & 0x3400 in (0x1400, 0x2400, 0x2000), 15.0)
    return h


@pytest.mark.parametrize("method", sorted(EXPECTED_REFERENCE))
def test_homing_method_finds_its_reference(harness, method):
    h = run_homing(harness, method)
    assert h.status & 0x3400 == 0x1400, f"homing error, status {h.status:#06x}"
    turns_now = h.drive.physics.load_turns
    expected = HOME_OFFSET + (turns_now - EXPECTED_REFERENCE[method]) * REV
    tolerance = INDEX_TOLERANCE if method in INDEX_METHODS else EDGE_TOLERANCE
    assert h.read(0x6064) == pytest.approx(expected, abs=tolerance)
    assert h.read(0x3218) == 1
    if method != 35:
        assert abs(h.read(0x6064) - HOME_OFFSET) <= EDGE_TOLERANCE + 2  # ended on the home position


def test_homing_without_moving_back_stays_where_it_found_home(harness):
    h = run_homing(harness, 34, end_on_home=0)
    assert h.status & 0x1000
    position = h.read(0x6064)
    expected = HOME_OFFSET + (h.drive.physics.load_turns - 0.3) * REV
    assert position == pytest.approx(expected, abs=INDEX_TOLERANCE)
    assert position != HOME_OFFSET


def test_homing_without_a_home_switch_reports_a_homing_error(harness):
    h = run_homing(harness, 8, plant=replace(PLANT, home_switch=None))
    assert h.status & 0x2000
    assert h.read(0x3218) == 0


def test_unsupported_method_is_a_homing_error(harness):
    h = run_homing(harness, 15)
    assert h.status & 0x2000


def test_homing_start_when_not_enabled_is_an_error_except_method_35(harness):
    h = harness(plant=PLANT)
    h.write(0x6060, 0, 6)
    h.write(0x6098, 0, 1)
    h.control(0x10)
    assert h.status & 0x2000
    h2 = harness(plant=PLANT)
    h2.write(0x6060, 0, 6)
    h2.write(0x6098, 0, 35)
    h2.write(0x607C, 0, 77)
    h2.control(0x10)
    h2.run(0.002)
    assert h2.read(0x6064) == 77
