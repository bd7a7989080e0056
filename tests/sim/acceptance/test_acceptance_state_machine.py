"""Every CiA 402 transition of the simulated XtrapulsPac, walked by canopen's BaseNode402 over socketcand.

Transition numbers are the manual's (§3.2.1.1). The state is always read back from the status word the drive sent.
Automatic transitions (12 after a ramp, 13/14 on a fault) are checked in the trace of every status word change
(TPDO 4, event-driven, with the position the drive had at that instant).
"""

from __future__ import annotations

from tests.support.canopen_axis import (
    CW_CHANGE_IMMEDIATELY,
    CW_ENABLE_OPERATION,
    CW_NEW_SET_POINT,
    REV,
    STATUS_TARGET_REACHED,
    Axis,
    Sample,
    state_of,
)

QUICK_STOP_CODE = 0x605A
TARGET_VELOCITY = 0x60FF
CONTROL_QUICK_STOP = 0x02


def enable(axis: Axis) -> None:
    """Transitions 2, 3, 4 one at a time."""
    for state in ("READY TO SWITCH ON", "SWITCHED ON", "OPERATION ENABLED"):
        axis.go(state)


def coast_after(axis: Axis, sample: Sample) -> int:
    """User units the axis still travels after the drive reported `sample`. A drive that switched off at
    10 rev/s would let the default machine coast about 2 rev; after a ramp to standstill it is a few units."""
    return abs(axis.wait_standstill() - sample.position)


def run_at_speed(axis: Axis, velocity: int) -> None:
    """Profile velocity at `velocity` (user units/s): the measured speed gets there, the drive reports it."""
    axis.set_mode("PROFILED VELOCITY")
    axis.write(0x6083, 200 * REV)
    axis.write(TARGET_VELOCITY, velocity)
    axis.wait_value(0x606C, lambda speed: abs(speed - velocity) < REV // 4, f"speed {velocity}")
    axis.wait_status(lambda status: status & STATUS_TARGET_REACHED, "PV target reached")


def test_power_up_shows_switch_on_disabled_and_the_enable_path(axis: Axis):
    assert state_of(axis.read(0x6041)) == "SWITCH ON DISABLED"  # transition 1 happened at power-up
    enable(axis)
    assert axis.read(0x6041) & 0x6F == 0x27


def test_back_from_operation_enabled_by_every_command(axis: Axis):
    enable(axis)
    axis.go("SWITCHED ON")  # 5 disable operation
    axis.go("READY TO SWITCH ON")  # 6 shutdown
    axis.go("SWITCH ON DISABLED")  # 7 disable voltage
    enable(axis)
    axis.go("READY TO SWITCH ON")  # 8 shutdown from operation enabled
    axis.go("SWITCHED ON")
    axis.go("SWITCH ON DISABLED")  # 10 disable voltage from switched on
    enable(axis)
    axis.go("SWITCH ON DISABLED")  # 9 disable voltage from operation enabled


def test_quick_stop_command_before_operation_disables_voltage(axis: Axis):
    axis.go("READY TO SWITCH ON")
    axis.command(CONTROL_QUICK_STOP, "SWITCH ON DISABLED")  # 7
    axis.go("SWITCHED ON")
    axis.command(CONTROL_QUICK_STOP, "SWITCH ON DISABLED")  # 10


def test_quick_stop_that_stays_active_then_disable_voltage_and_back_to_operation(axis: Axis):
    axis.write(QUICK_STOP_CODE, 6)  # quick-stop ramp, then stay in QUICK STOP ACTIVE: transition 16 allowed
    enable(axis)
    run_at_speed(axis, 10 * REV)
    mark = len(axis.trace)
    axis.go("QUICK STOP ACTIVE")  # 11
    axis.wait_status(lambda status: status & STATUS_TARGET_REACHED, "quick stop ended (target reached)")
    entered = axis.first_sample(mark, lambda s: s.state == "QUICK STOP ACTIVE", "quick stop active")
    ended = axis.first_sample(
        mark, lambda s: s.state == "QUICK STOP ACTIVE" and s.status & STATUS_TARGET_REACHED, "quick stop ended"
    )
    assert abs(ended.position - entered.position) < REV // 4  # the 0x6085 ramp: 0.1 rev from 10 rev/s
    assert coast_after(axis, ended) < REV // 64  # holding
    assert state_of(axis.read(0x6041)) == "QUICK STOP ACTIVE"
    axis.write(TARGET_VELOCITY, 0)
    axis.go("OPERATION ENABLED")  # 16
    axis.go("QUICK STOP ACTIVE")  # 11 again, at standstill
    axis.go("SWITCH ON DISABLED")  # 12 by disable voltage


def test_quick_stop_with_ramp_code_ends_in_switch_on_disabled_by_itself(axis: Axis):
    axis.write(QUICK_STOP_CODE, 2)  # quick-stop ramp (0x6085), then transition 12 automatically
    enable(axis)
    run_at_speed(axis, 10 * REV)
    mark = len(axis.trace)
    axis.command(CONTROL_QUICK_STOP, "SWITCH ON DISABLED")
    assert axis.states_since(mark) == ["QUICK STOP ACTIVE", "SWITCH ON DISABLED"]
    entered = axis.first_sample(mark, lambda s: s.state == "QUICK STOP ACTIVE", "quick stop active")
    disabled = axis.first_sample(mark, lambda s: s.state == "SWITCH ON DISABLED", "switch on disabled")
    assert abs(disabled.position - entered.position) < REV // 4
    assert coast_after(axis, disabled) < REV // 64


def test_following_error_fault_reaction_then_fault_reset(axis: Axis):
    axis.write(0x3025, 1 << (35 - 33), sub=4)  # error 35 (position following) reacts with Stop 2, not Stop 0
    axis.write(0x205F, 2)  # EMCY also on fault reset (the XtrapulsPac default 1 sends only the error)
    axis.write(0x6065, 1)  # following-error window: one user unit, any real move exceeds it
    enable(axis)
    axis.set_mode("PROFILED POSITION")
    axis.write(0x6081, 10 * REV)
    axis.write(0x6083, 100 * REV)
    axis.write(0x6084, 100 * REV)
    axis.write(0x607A, 20 * REV)
    mark = len(axis.trace)
    axis.node.controlword = CW_ENABLE_OPERATION | CW_NEW_SET_POINT | CW_CHANGE_IMMEDIATELY
    axis.wait_state("FAULT")
    assert axis.states_since(mark) == ["OPERATION ENABLED", "FAULT REACTION ACTIVE", "FAULT"]  # 13, 14
    assert axis.read(0x603F) == 0x8611
    assert axis.read(0x3022, sub=2) & (1 << (35 - 33))
    assert [emcy.code for emcy in axis.node.emcy.active] == [0x8611]
    assert abs(axis.wait_standstill()) < REV  # stopped at the start of the 20 rev move
    axis.write(0x6065, 0xFFFFFFFF)
    axis.go("SWITCH ON DISABLED")  # 15 fault reset (control word bit 7 rising)
    assert axis.read(0x603F) == 0
    assert axis.node.emcy.active == []  # the drive sent the error-reset EMCY
    enable(axis)


def test_disable_operation_and_shutdown_while_moving_stop_the_axis_first(axis: Axis):
    axis.write(0x605B, 1)  # shutdown: slow-down ramp before the power stage switches off
    axis.write(0x3300, 200 * REV, sub=1)  # slow-down ramp (Stop 1) of 0x605B/0x605C = 1
    enable(axis)
    for state in ("SWITCHED ON", "READY TO SWITCH ON"):  # 5 (0x605C = 1), then 8 (0x605B = 1)
        run_at_speed(axis, 10 * REV)
        mark = len(axis.trace)
        axis.go(state)
        assert axis.states_since(mark) == [state]
        reported = axis.first_sample(mark, lambda s, state=state: s.state == state, state)
        assert coast_after(axis, reported) < REV // 64, f"the axis was still moving when {state} was reported"
        axis.go("OPERATION ENABLED")
