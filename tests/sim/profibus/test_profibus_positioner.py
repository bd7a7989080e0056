"""The simulated TTA-PRO's PZD state machine and modes (TTA-PRO Profibus Communication Profile, Chapter 2):
enabling stages and the OFF priorities, jog, homing, moves and stops in positioner mode, speed and torque modes,
faults and their acknowledge."""

from __future__ import annotations

import struct

from tests.support.ttapro_rig import ENABLED, Rig

from servostudio.sim.plant import Plant

INHIBITED, READY_FOR_ENABLE, READY, OPERATION = 0x0040, 0x0001, 0x0003, 0x0007
STATE = 0x004F
FAULT, NO_FOLLOWING_ERROR, HOME_FOUND, POSITION_REACHED = 0x0008, 0x0100, 0x0800, 0x0400
JOG_PLUS, JOG_MINUS, HOMING, RELATIVE = 0x0100, 0x0200, 0x0800, 0x2000
INCREMENTS = 4096


def test_the_enabling_stages_follow_the_manuals_example(rig: Rig) -> None:
    assert rig.control(0x0000) & STATE == INHIBITED
    assert rig.control(0x0400) & STATE == INHIBITED
    assert rig.control(0x0406) & STATE == READY_FOR_ENABLE
    assert rig.control(0x0407) & STATE == READY
    assert rig.control(ENABLED, cycles=5) & 0x033F == 0x0337


def test_without_profibus_control_the_drive_stays_inhibited(rig: Rig) -> None:
    for word in (0x0006, 0x0007, 0x003F):
        status = rig.control(word)
    assert status & STATE == INHIBITED
    assert not status & 0x0200  # operation in local mode


def test_off2_wins_over_off1_which_wins_over_off3(rig: Rig) -> None:
    rig.enable()
    assert rig.control(ENABLED & ~0x0003) & STATE == INHIBITED  # OFF2 and OFF1: OFF2, at once
    rig.enable()
    status = rig.control(ENABLED & ~0x0005, cycles=60)  # OFF1 and OFF3: OFF1, ramp then Ready for ENABLE
    assert status & STATE == READY_FOR_ENABLE


def test_jog_moves_while_held_and_stops_when_released(rig: Rig) -> None:
    rig.write(763, 600)
    rig.enable()
    rig.pzd[0] = ENABLED | JOG_PLUS
    rig.cycle(cycles=300)
    forward = rig.position()
    assert forward > INCREMENTS  # 600 rpm for about 0.3 s is about 2.5 rev
    rig.pzd[0] = ENABLED
    rig.run_until(lambda: abs(rig.drive.axis.speed) < 0.5 and not rig.drive.axis.moving, 2.0)
    stopped = rig.position()
    assert stopped > forward
    rig.pzd[0] = ENABLED | JOG_MINUS
    rig.cycle(cycles=100)
    assert rig.position() < stopped


def test_a_relative_move_toggles_the_acknowledge_and_ends_in_position(rig: Rig) -> None:
    rig.write(760, 1200)
    before = rig.enable()
    rig.command_position(3 * INCREMENTS)
    status = rig.control(ENABLED | RELATIVE, cycles=2)
    assert (status ^ before) & 0x1000
    rig.run_until(lambda: bool(rig.words[0] & POSITION_REACHED) and rig.drive.axis.stopped, 3.0)
    assert abs(rig.position() - 3 * INCREMENTS) < 40


def test_homing_on_switch_and_marker_sets_the_counter_to_the_offset(rig: Rig) -> None:
    rig.write(760, 1500)
    rig.write(766, 0x10 | 0x20 | 0x40 | 0x80)  # switch, marker, move onto home, reset counter
    rig.write(768, 1000)
    rig.enable()
    rig.control(ENABLED | HOMING, cycles=2)
    rig.run_until(lambda: bool(rig.words[0] & HOME_FOUND), 5.0)
    rig.run_until(lambda: rig.drive.axis.stopped, 1.0)
    assert abs(rig.position() - 1000) < 30
    physics = rig.drive.axis.physics
    assert physics.home_switch_active()


def test_a_positioning_stops_at_a_limit_switch_without_a_fault(parameters) -> None:
    rig = Rig(parameters, Plant(positive_limit_switch=1.5, positive_hard_stop=3.0, home_switch=None))
    rig.write(760, 600)
    rig.enable()
    rig.command_position(10 * INCREMENTS)
    rig.control(ENABLED | RELATIVE, cycles=2)
    rig.run_until(lambda: not rig.words[0] & NO_FOLLOWING_ERROR, 3.0)
    rig.run_until(lambda: rig.drive.axis.stopped, 1.0)
    status = rig.cycle()[0]
    assert status & STATE == OPERATION and not status & FAULT
    assert rig.read(769) & 1 << 4  # hardware limit switch +


def test_a_following_error_trips_and_the_acknowledge_clears_it(rig: Rig) -> None:
    rig.write(741, 20)
    rig.write(760, 3000)
    rig.write(761, 1)
    rig.enable()
    rig.command_position(20 * INCREMENTS)
    rig.control(ENABLED | RELATIVE, cycles=2)
    rig.run_until(lambda: bool(rig.words[0] & FAULT), 1.0)
    assert rig.read(755) == 12
    assert rig.read(773) & 1 << 3
    rig.control(0x0400 | 0x0080)
    assert rig.control(0x0400) & STATE == INHIBITED


def test_parameters_for_a_disabled_positioner_are_refused_while_enabled(rig: Rig) -> None:
    rig.enable()
    assert rig.write(720, 2)[0::3] == (7, 17)
    assert rig.write(700, 3)[0::3] == (7, 17)


def test_speed_mode_follows_pzd2_and_reports_the_speed_in_it(rig: Rig) -> None:
    assert rig.write(720, 2)[0] == 1
    rig.write(723, 100)  # 50 ms to maximum speed
    rig.pzd[1] = 32767 // 4
    rig.enable()
    rig.cycle(cycles=300)
    speed_rpm = rig.drive.axis.speed * 60 / (2 * 3.141592653589793)
    assert abs(speed_rpm - rig.read(721) / 4) < 50
    assert abs(struct.unpack(">h", struct.pack(">H", rig.words[1]))[0] - 32767 // 4) < 500
    assert rig.words[0] & 0x8000  # speed reached


def test_torque_mode_turns_the_current_command_into_current(rig: Rig) -> None:
    rig.write(720, 1)
    rig.pzd[1] = 32767 // 10
    rig.enable()
    rig.cycle(cycles=20)
    rating = rig.drive.units.rating
    assert abs(rig.drive.axis.loops.i_q - rating / 10) < 0.1 * rating
    assert rig.drive.axis.speed > 0


def test_off3_and_the_stop_bit_brake_at_the_current_limit(rig: Rig) -> None:
    rig.write(763, 1500)
    rig.enable()
    rig.pzd[0] = ENABLED | JOG_PLUS
    rig.cycle(cycles=200)
    rig.pzd[0] = (ENABLED | JOG_PLUS) & ~0x0010  # CW4 = 0: stop, stays enabled
    rig.run_until(lambda: rig.drive.axis.stopped, 0.5)
    assert rig.cycle()[0] & STATE == OPERATION
    rig.pzd[0] = ENABLED & ~0x0004  # OFF3
    rig.run_until(lambda: rig.words[0] & STATE == INHIBITED, 0.5)
