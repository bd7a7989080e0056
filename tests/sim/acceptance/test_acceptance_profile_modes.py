"""Profile position and profile velocity moves of the simulated XtrapulsPac, commanded by canopen's BaseNode402 over
socketcand: set-point handshake through the control word, target reached in the status word, the actual values
read back by SDO."""

from __future__ import annotations

from tests.support.canopen_axis import (
    REV,
    STATUS_SET_POINT_ACK,
    STATUS_TARGET_REACHED,
    Axis,
)

POSITION_WINDOW = 20  # user units (1/4096 rev)
VELOCITY_WINDOW = REV // 4  # user units/s; the speed measurement is quantised to 1 count per 250 µs


def enable(axis: Axis, mode: str) -> None:
    axis.set_mode(mode)
    for state in ("READY TO SWITCH ON", "SWITCHED ON", "OPERATION ENABLED"):
        axis.go(state)


def test_profile_position_absolute_then_relative_move(axis: Axis):
    enable(axis, "PROFILED POSITION")
    axis.write(0x6067, POSITION_WINDOW)
    axis.write(0x6068, 10)  # ms inside the window before SW10
    axis.write(0x6081, 10 * REV)  # profile velocity: 10 rev/s
    axis.write(0x6083, 100 * REV)
    axis.write(0x6084, 100 * REV)
    start = axis.read(0x6064)
    assert abs(start) <= POSITION_WINDOW

    axis.move(5 * REV)
    assert abs(axis.read(0x6064) - 5 * REV) <= POSITION_WINDOW

    axis.move(-2 * REV, relative=True)  # relative to the last target
    assert abs(axis.read(0x6064) - 3 * REV) <= POSITION_WINDOW
    assert abs(axis.read(0x606C)) < VELOCITY_WINDOW


def test_profile_velocity_reaches_the_target_speed_then_zero(axis: Axis):
    enable(axis, "PROFILED VELOCITY")
    axis.write(0x606D, VELOCITY_WINDOW)
    axis.write(0x606E, 10)  # ms inside the window before SW10
    axis.write(0x606F, VELOCITY_WINDOW)  # speed = 0 threshold (SW12)
    axis.write(0x6070, 10)
    axis.write(0x6083, 200 * REV)
    axis.write(0x6084, 200 * REV)
    axis.wait_status(lambda s: s & STATUS_SET_POINT_ACK, "standstill (SW12 speed = 0)")
    target = 8 * REV
    axis.write(0x60FF, target)
    axis.wait_status(lambda s: not s & STATUS_SET_POINT_ACK, "moving (SW12 speed = 0 cleared)")
    axis.wait_status(lambda s: s & STATUS_TARGET_REACHED, "target velocity reached (SW10)")
    assert abs(axis.read(0x606C) - target) <= VELOCITY_WINDOW
    position = axis.read(0x6064)
    assert axis.read(0x6064) != position  # it really turns

    axis.write(0x60FF, 0)
    axis.wait_status(
        lambda s: s & STATUS_TARGET_REACHED and s & STATUS_SET_POINT_ACK, "zero speed reached (SW10 and SW12)"
    )
    assert abs(axis.read(0x606C)) <= VELOCITY_WINDOW
