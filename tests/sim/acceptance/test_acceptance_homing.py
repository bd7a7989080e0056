"""Homing of the simulated XtrapulsPac with canopen's `BaseNode402.homing()` over socketcand, for references of
different kinds: the current position (35), the first index pulse (34) and the negative limit switch (17).

After homing the position actual 0x6064 reads the home offset 0x607C (the drive moves back onto the reference,
0x309D = 1), and the sensor counter 0x6063, which homing does not touch, shows where that reference is: the
default machine (docs/sim-plant.md) has its negative limit switch at −20 rev and the index pulse at 0.25 rev of
each motor turn; the axis powers up at 0.
"""

from __future__ import annotations

import pytest
from tests.support.canopen_axis import REV, Axis

HOME_OFFSET = 12_345
TOLERANCE = 20  # user units (1/4096 rev): the position loop's rest error
NEGATIVE_LIMIT_INPUT = 1 << 0  # 0x60FD
SENSOR_COUNTS = 65_536  # 0x6063 per motor revolution, zero where the axis powered up (not moved by homing)


def configure_homing(axis: Axis, method: int) -> None:
    axis.write(0x6098, method)
    axis.write(0x6099, 40 * REV, sub=1)  # search speed: 40 rev/s
    axis.write(0x6099, 2 * REV, sub=2)  # approach / index speed: 2 rev/s
    axis.write(0x609A, 2000 * REV)
    axis.write(0x607C, HOME_OFFSET)


def home(axis: Axis, method: int) -> None:
    configure_homing(axis, method)
    axis.set_mode("PROFILED POSITION")
    assert axis.node.homing(timeout=10, restore_op_mode=True), f"homing method {method} did not succeed"
    assert axis.node.op_mode == "PROFILED POSITION"  # restored
    assert axis.node.is_homed(restore_op_mode=True)
    assert axis.read(0x3218) == 1  # homing indicator


@pytest.mark.parametrize(("method", "reference_turns"), [(35, 0.0), (34, 0.25)])
def test_homing_on_current_position_and_on_index_pulse(axis: Axis, method: int, reference_turns: float):
    """35: where the axis stands (its power-up place); 34: the first index pulse moving positive."""
    before = axis.read(0x6064)
    assert abs(before - HOME_OFFSET) > REV
    home(axis, method)
    assert abs(axis.read(0x6064) - HOME_OFFSET) <= TOLERANCE
    assert abs(axis.read(0x6063) - reference_turns * SENSOR_COUNTS) <= TOLERANCE * SENSOR_COUNTS // REV


def test_homing_on_negative_limit_switch_takes_its_edge(axis: Axis):
    home(axis, 17)
    assert abs(axis.read(0x6064) - HOME_OFFSET) <= TOLERANCE
    assert abs(axis.read(0x6063) - (-20 * SENSOR_COUNTS)) <= TOLERANCE * SENSOR_COUNTS // REV
    assert not axis.read(0x60FD) & NEGATIVE_LIMIT_INPUT
    # the reference is the switch edge: a move from above towards an eighth of a turn below it stops at the edge
    axis.write(0x6081, REV)
    axis.write(0x6083, 100 * REV)
    axis.write(0x6084, 100 * REV)
    axis.move(HOME_OFFSET + REV // 8)
    assert not axis.read(0x60FD) & NEGATIVE_LIMIT_INPUT
    axis.move(HOME_OFFSET - REV // 8, until="stop at the limit switch (target reached)")
    assert axis.read(0x60FD) & NEGATIVE_LIMIT_INPUT
    assert abs(axis.read(0x6064) - HOME_OFFSET) < REV // 32
