"""The verdict on writes, judged on what the drive will do: the CiA 402 transition from the drive's state, the
device profile's motion objects, the values after the dictionary's conversion (no drive needed: the simulated
drives confirm the transitions in tests/api/test_api_motion_guard_holes.py)."""

from __future__ import annotations

import pytest

from servostudio.drive.access import PlannedWrite
from servostudio.drive.cia402 import State, transition
from servostudio.drive.profiles import profile_for
from servostudio.drive.profiles.base import signature_value
from servostudio.services.motion.verdict import Motion, MotionObjects, judge

XTRAPULSPAC = MotionObjects.of(profile_for("xtrapulspac"))
CONTROLWORD, TARGET_VELOCITY, GAIN = (0x6040, 0), (0x60FF, 0), (0x60F9, 2)


def write(key: tuple[int, int], raw: object) -> PlannedWrite:
    return PlannedWrite(key[0], key[1], raw)  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("state", "controlword", "after"),
    [
        (State.SWITCH_ON_DISABLED, 0x06, State.READY_TO_SWITCH_ON),
        (State.SWITCH_ON_DISABLED, 0x0F, State.SWITCH_ON_DISABLED),  # no transition: Shutdown first
        (State.READY_TO_SWITCH_ON, 0x07, State.SWITCHED_ON),
        (State.READY_TO_SWITCH_ON, 0x0F, State.OPERATION_ENABLED),  # transitions 3 + 4 in one write
        (State.SWITCHED_ON, 0x0F, State.OPERATION_ENABLED),
        (State.SWITCHED_ON, 0x8F, State.OPERATION_ENABLED),  # bit 7 does not stop bits 3-0 from enabling
        (State.SWITCHED_ON, 0x1F, State.OPERATION_ENABLED),  # mode bits do not matter for the state
        (State.OPERATION_ENABLED, 0x02, State.QUICK_STOP_ACTIVE),
        (State.OPERATION_ENABLED, 0x07, State.SWITCHED_ON),
        (State.OPERATION_ENABLED, 0x00, State.SWITCH_ON_DISABLED),
        (State.QUICK_STOP_ACTIVE, 0x0F, State.OPERATION_ENABLED),  # transition 16, assumed possible
        (State.FAULT, 0x0F, State.FAULT),
        (State.FAULT, 0x80, State.SWITCH_ON_DISABLED),
        (State.FAULT, 0x86, State.READY_TO_SWITCH_ON),  # the reset, then the command from SWITCH ON DISABLED
    ],
)
def test_transition_is_the_drive_s(state, controlword, after):
    assert transition(state, controlword) is after


@pytest.mark.parametrize(
    ("state", "writes", "motion", "enables"),
    [
        (State.SWITCHED_ON, [write(CONTROLWORD, 0x0F)], Motion.MOVES, True),
        (State.SWITCHED_ON, [write(CONTROLWORD, 0x8F)], Motion.MOVES, True),
        (State.SWITCH_ON_DISABLED, [write(CONTROLWORD, 0x0F)], Motion.PREPARES, False),
        (State.SWITCH_ON_DISABLED, [write(CONTROLWORD, 0x06), write(CONTROLWORD, 0x0F)], Motion.MOVES, True),
        (State.OPERATION_ENABLED, [write(CONTROLWORD, 0x1F)], Motion.MOVES, False),  # new set-point bit
        (State.OPERATION_ENABLED, [write(TARGET_VELOCITY, 500)], Motion.MOVES, False),
        (State.SWITCHED_ON, [write(TARGET_VELOCITY, 500)], Motion.PREPARES, False),
        (State.OPERATION_ENABLED, [write(GAIN, 77)], Motion.NONE, False),
        (None, [write(TARGET_VELOCITY, 500)], Motion.MOVES, False),  # a state the status word does not tell
    ],
)
def test_judge_plays_the_batch_through_the_state_machine(state, writes, motion, enables):
    verdict = judge(XTRAPULSPAC, state, writes)
    assert (verdict.motion, verdict.enables) == (motion, enables), verdict.reason


def test_stopping_is_a_stop_and_says_so():
    verdict = judge(XTRAPULSPAC, State.OPERATION_ENABLED, [write(CONTROLWORD, 0x02)])
    assert verdict.motion is Motion.STOPS and verdict.stops
    assert "OPERATION ENABLED to QUICK STOP ACTIVE" in verdict.reason


@pytest.mark.parametrize(
    ("state", "controlword"),
    [(State.SWITCHED_ON, 0x06), (State.READY_TO_SWITCH_ON, 0x00), (State.QUICK_STOP_ACTIVE, 0x00)],
)
def test_walking_down_the_ladder_is_a_stop_anyone_may_make(state, controlword):
    verdict = judge(XTRAPULSPAC, state, [write(CONTROLWORD, controlword)])
    assert verdict.motion is Motion.STOPS and not verdict.stops  # the axis was not running: no "stop" to log


@pytest.mark.parametrize("state", [State.SWITCH_ON_DISABLED, State.FAULT, State.QUICK_STOP_ACTIVE])
@pytest.mark.parametrize("controlword", [0x02, 0x00, 0x0B, 0x0433 & 0x0F])
def test_a_quick_stop_or_disable_voltage_is_a_stop_in_every_state(state, controlword):
    """Even where it changes nothing (an axis already disabled): the watchdog of a hold must never be refused."""
    assert judge(XTRAPULSPAC, state, [write(CONTROLWORD, controlword)]).motion is Motion.STOPS


def test_walking_up_the_ladder_prepares_motion():
    assert judge(XTRAPULSPAC, State.SWITCH_ON_DISABLED, [write(CONTROLWORD, 0x06)]).motion is Motion.PREPARES
    assert judge(XTRAPULSPAC, State.FAULT, [write(CONTROLWORD, 0x80)]).motion is Motion.PREPARES  # fault reset


def test_a_stop_followed_by_a_target_is_judged_by_its_gravest_write():
    verdict = judge(XTRAPULSPAC, State.OPERATION_ENABLED, [write(CONTROLWORD, 0x07), write(TARGET_VELOCITY, 9)])
    assert verdict.motion is Motion.PREPARES and verdict.stops


def test_procedures_that_turn_the_motor_are_motion_even_with_the_drive_disabled():
    start_phasing = write((0x3413, 0), signature_value("apha"))
    assert judge(XTRAPULSPAC, State.SWITCH_ON_DISABLED, [start_phasing]).motion is Motion.MOVES
    assert judge(XTRAPULSPAC, State.SWITCH_ON_DISABLED, [write((0x3413, 0), 0)]).motion is Motion.NONE
    cd1k = MotionObjects.of(profile_for("cd1k"))
    assert judge(cd1k, State.SWITCH_ON_DISABLED, [write((0x3420, 2), signature_value("atun"))]).motion is Motion.MOVES


def test_the_profile_s_own_motion_objects_count():
    analog_velocity = write((0x30FF, 0), 0x30F10200)  # the target velocity follows analog input 1 from now on
    assert judge(XTRAPULSPAC, State.OPERATION_ENABLED, [analog_velocity]).motion is Motion.MOVES
    generic = MotionObjects.of(profile_for("unknown-device"))
    assert judge(generic, State.OPERATION_ENABLED, [analog_velocity]).motion is Motion.NONE


def test_a_control_word_that_is_no_integer_is_never_let_through():
    assert (
        judge(XTRAPULSPAC, State.SWITCH_ON_DISABLED, [write(CONTROLWORD, b"\x0f\x00\x00\x00\x00")]).motion
        is Motion.MOVES
    )
