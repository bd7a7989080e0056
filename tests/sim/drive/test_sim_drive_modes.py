"""Operation modes: PP handshake and target window, PV bits and halt, PT, IP on SYNC, limit switches."""

from __future__ import annotations

from dataclasses import replace

import pytest

from servostudio.sim.plant import Plant

REV = 4096
TARGET_REACHED, ACK, BIT13 = 1 << 10, 1 << 12, 1 << 13


def pp_ready(h, window: int = 20, window_time: int = 10):
    h.write(0x6067, 0, window)
    h.write(0x6068, 0, window_time)
    h.write(0x6081, 0, REV * 20)
    h.write(0x6083, 0, REV * 200)
    h.write(0x6084, 0, REV * 200)
    h.enable(1)


def new_set_point(h, target: int, control_word: int = 0x1F) -> None:
    h.write(0x607A, 0, target)
    h.control(control_word)
    h.control(control_word & ~0x10)


def test_pp_move_reaches_target_within_window_and_sets_target_reached(harness):
    h = harness()
    pp_ready(h)
    start = h.read(0x6064)
    assert h.status & TARGET_REACHED
    h.write(0x607A, 0, start + REV * 5)
    h.control(0x1F)
    assert h.status & ACK  # set-point acknowledge while bit 4 is high
    assert not h.status & TARGET_REACHED
    h.control(0x0F)
    assert not h.status & ACK
    h.run_until(lambda: h.status & TARGET_REACHED, 2.0)
    assert abs(h.read(0x6064) - (start + REV * 5)) <= 20
    assert h.read(0x6062) == start + REV * 5


def test_pp_target_reached_waits_for_the_window_time(harness):
    h = harness()
    pp_ready(h, window=20, window_time=200)
    start = h.read(0x6064)
    new_set_point(h, start + REV)
    h.run_until(lambda: h.drive.handlers[1].generator.done, 1.0)
    h.run(0.1)
    assert not h.status & TARGET_REACHED  # in the window for less than 200 ms
    h.run(0.15)
    assert h.status & TARGET_REACHED


def test_pp_relative_move_adds_to_the_last_target(harness):
    h = harness()
    pp_ready(h)
    start = h.read(0x6064)
    new_set_point(h, start + REV)
    h.run_until(lambda: h.status & TARGET_REACHED, 2.0)
    new_set_point(h, REV * 2, control_word=0x5F)  # bit 6: relative
    h.run_until(lambda: h.status & TARGET_REACHED, 2.0)
    assert abs(h.read(0x6064) - (start + REV * 3)) <= 20


def test_pp_change_immediately_replaces_the_running_move(harness):
    h = harness()
    pp_ready(h)
    start = h.read(0x6064)
    new_set_point(h, start + REV * 10)
    h.run(0.1)
    new_set_point(h, start - REV, control_word=0x3F)  # bit 5: change set immediately
    h.run_until(lambda: h.status & TARGET_REACHED, 3.0)
    assert abs(h.read(0x6064) - (start - REV)) <= 20


def test_pp_buffered_set_point_runs_after_the_first(harness):
    h = harness()
    pp_ready(h)
    start = h.read(0x6064)
    new_set_point(h, start + REV * 2)
    h.run(0.05)
    new_set_point(h, start + REV * 4)  # bit 5 = 0: queued
    assert not h.status & TARGET_REACHED
    h.run_until(lambda: abs(h.read(0x6064) - (start + REV * 2)) < 100, 2.0)
    h.run_until(lambda: h.status & TARGET_REACHED, 3.0)
    assert abs(h.read(0x6064) - (start + REV * 4)) <= 20


def test_pv_target_reached_and_speed_zero_bits_and_halt(harness):
    h = harness()
    h.write(0x606D, 0, 100)
    h.write(0x606E, 0, 20)
    h.write(0x606F, 0, 50)
    h.write(0x6070, 0, 20)
    h.write(0x6083, 0, REV * 100)
    h.write(0x6084, 0, REV * 100)
    h.enable(3)
    h.run(0.05)
    assert h.status & ACK  # speed = 0
    h.write(0x60FF, 0, REV * 5)
    h.run(0.03)
    assert not h.status & ACK
    assert not h.status & TARGET_REACHED
    h.run(0.2)
    assert h.status & TARGET_REACHED
    assert abs(h.read(0x606C) - REV * 5) <= 100
    h.control(0x10F)  # halt
    h.run(0.2)
    assert abs(h.read(0x606C)) <= 50
    assert h.status & ACK


def test_pt_follows_target_torque_with_its_slope(harness):
    h = harness()
    h.write(0x6087, 0, 1000)  # 1000 ‰ per second
    h.enable(4)
    h.write(0x6071, 0, 300)
    h.run(0.1)
    assert h.read(0x6074) == pytest.approx(100, abs=3)  # 0.1 s at 1000 ‰/s
    assert not h.status & TARGET_REACHED
    h.run(0.25)
    assert h.read(0x6074) == 300
    assert h.status & TARGET_REACHED


def test_ip_moves_through_the_set_points_given_on_sync(harness):
    h = harness()
    h.write(0x1006, 0, 2000)  # 2 ms SYNC
    h.enable(7)
    start = h.read(0x6064)
    h.control(0x1F)  # enable ip
    assert h.status & ACK
    target = start
    for _ in range(200):
        target += 8  # 8 increments per 2 ms = 4000 inc/s
        h.write(0x60C1, 1, target)
        h.drive.on_sync()
        h.run(0.002)
    assert abs(h.read(0x6062) - target) <= 8
    assert abs(h.read(0x6064) - target) < 40
    assert h.read(0x606C) == pytest.approx(4000, rel=0.05)


def test_limit_switch_stops_pv_motion_towards_it_and_sets_the_warning(harness):
    plant = replace(Plant.commissioned(), positive_limit_switch=1.0, positive_hard_stop=3.0)
    h = harness(plant=plant)
    h.write(0x6083, 0, REV * 50)
    h.write(0x6084, 0, REV * 50)
    h.enable(3)
    h.write(0x60FF, 0, REV * 5)
    h.run_until(lambda: h.read(0x60FD) & 0x2, 2.0)
    h.run(0.3)
    assert abs(h.read(0x606C)) < 50
    assert h.read(0x3024) & (1 << 16)
    assert h.status & 0x80
    h.write(0x60FF, 0, -REV * 5)  # away from the switch is allowed
    h.run_until(lambda: not h.read(0x60FD) & 0x2, 2.0)
    h.run(0.01)
    assert not h.read(0x3024) & (1 << 16)


def max_jerk_of_move(h, profile_type: int) -> float:
    h.write(0x6086, 0, profile_type)
    pp_ready(h)
    start = h.read(0x6064)
    new_set_point(h, start + REV * 3)
    loops = h.drive.loops
    previous, jerk = loops.accel_ff, 0.0
    for _ in range(2000):
        h.run(0.00025)
        jerk = max(jerk, abs(loops.accel_ff - previous))
        previous = loops.accel_ff
        if h.status & TARGET_REACHED:
            break
    assert h.status & TARGET_REACHED
    assert abs(h.read(0x6064) - (start + REV * 3)) <= 20
    return jerk


def test_pp_s_curve_reaches_the_same_target_with_limited_jerk(harness):
    trapezoid = max_jerk_of_move(harness(), 0)
    s_curve = max_jerk_of_move(harness(), -1)
    assert s_curve < trapezoid / 20


def test_ip_missing_set_point_is_error_50(harness):
    h = harness()
    h.write(0x1006, 0, 2000)
    h.enable(7)
    h.control(0x1F)
    target = h.read(0x6064)
    for _ in range(10):
        h.write(0x60C1, 1, target)
        h.drive.on_sync()
        h.run(0.002)
    assert h.status & 0x0F != 0x08
    h.drive.on_sync()  # no set-point this cycle
    h.run(0.002)
    assert h.status & 0x0F == 0x08
    assert h.read(0x3022, 2) == 1 << 17  # code 50
    assert h.events.emergencies[-1][:2] == (0x8782, 50)
