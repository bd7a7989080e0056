"""CiA 402 device control at the behaviour level: every transition, with the status words of the manual."""

from __future__ import annotations

import pytest

from servostudio.sim.drive import errors
from servostudio.sim.drive.statemachine import State

MASK = 0x6F
SOD, RTSO, SO, OE, QSA, FRA, FAULT = 0x40, 0x21, 0x23, 0x27, 0x07, 0x0F, 0x08


def state_of(h) -> State:
    return h.drive.device_control.state


def test_power_up_is_switch_on_disabled_with_remote_bit(harness):
    h = harness()
    h.run(0.001)
    assert h.status == 0x0240  # manual L3102: 0x0000 -> 0x0240
    assert h.drive.device_control.transition == 1


def test_enable_sequence_gives_the_manuals_status_words(harness):
    h = harness()
    expected = [(0x00, 0x0240), (0x06, 0x0221), (0x07, 0x0223), (0x0F, 0x0227)]
    for control_word, status in expected:
        h.control(control_word)
        assert h.status & 0x7FFF & ~0x0400 == status, (hex(control_word), hex(h.status))
    assert h.drive.device_control.power_on


@pytest.mark.parametrize(
    ("path", "final", "transition"),
    [
        ([0x06], RTSO, 2),
        ([0x06, 0x07], SO, 3),
        ([0x06, 0x07, 0x0F], OE, 4),
        ([0x06, 0x07, 0x0F, 0x07], SO, 5),
        ([0x06, 0x07, 0x06], RTSO, 6),
        ([0x06, 0x00], SOD, 7),
        ([0x06, 0x02], SOD, 7),
        ([0x06, 0x07, 0x0F, 0x06], RTSO, 8),
        ([0x06, 0x07, 0x0F, 0x00], SOD, 9),
        ([0x06, 0x07, 0x00], SOD, 10),
        ([0x06, 0x07, 0x02], SOD, 10),
        ([0x06, 0x07, 0x0F, 0x02], SOD, 12),
        ([0x06, 0x0F], OE, 4),
    ],
)
def test_transitions(harness, path, final, transition):
    h = harness()
    h.write(0x6060, 0, 3)
    for control_word in path:
        h.control(control_word, settle=0.05)
    assert h.status & MASK == final, hex(h.status)
    assert h.drive.device_control.transition == transition


def test_quick_stop_with_code_6_stays_in_quick_stop_and_16_returns_to_operation(harness):
    h = harness()
    h.write(0x605A, 0, 6)
    h.enable(3)
    h.write(0x60FF, 0, 4096 * 20)
    h.run(0.3)
    h.control(0x0B)  # quick stop: bit 2 = 0
    assert h.status & MASK == QSA
    h.run_until(lambda: abs(h.read(0x606C)) < 200, 1.0)
    h.run(0.05)
    assert h.status & MASK == QSA  # code 6 stays in Quick Stop Active
    assert h.drive.device_control.power_on
    h.control(0x0F)
    assert h.status & MASK == OE
    assert h.drive.device_control.transition == 16


def test_quick_stop_with_code_2_decelerates_on_0x6085_then_switches_off(harness):
    h = harness()
    h.write(0x605A, 0, 2)
    h.write(0x6085, 0, 4096 * 100)  # 100 rev/s²
    h.write(0x6083, 0, 4096 * 200)
    h.enable(3)
    h.write(0x60FF, 0, 4096 * 20)  # 20 rev/s
    h.run(0.5)
    h.control(0x0B)
    assert h.status & MASK == QSA
    elapsed = h.run_until(lambda: h.status & MASK == SOD, 2.0)
    assert 0.15 < elapsed < 0.3  # 20 rev/s at 100 rev/s² takes 0.2 s
    assert not h.drive.device_control.power_on
    assert h.drive.device_control.transition == 12


def test_disable_operation_code_1_ramps_down_before_switched_on(harness):
    h = harness()
    h.write(0x605C, 0, 1)
    h.write(0x3300, 1, 4096 * 50)
    h.write(0x6083, 0, 4096 * 200)
    h.enable(3)
    h.write(0x60FF, 0, 4096 * 10)
    h.run(0.5)
    h.control(0x07)
    assert h.status & MASK == OE  # the ramp runs in Operation Enabled
    elapsed = h.run_until(lambda: h.status & MASK == SO, 2.0)
    assert elapsed > 0.1
    assert h.drive.device_control.transition == 5


def test_shutdown_code_0_switches_off_at_once(harness):
    h = harness()
    h.enable(3)
    h.write(0x60FF, 0, 4096 * 10)
    h.run(0.3)
    h.control(0x06, settle=0.00025)
    assert not h.drive.device_control.power_on
    assert h.status & MASK == RTSO


def test_fault_reaction_and_fault_reset_rising_edge(harness):
    h = harness()
    h.enable(3)
    h.drive.raise_error(errors.I2T)
    h.run(0.001)
    assert h.status & MASK == FAULT
    assert state_of(h) is State.FAULT
    assert h.drive.device_control.transition == 14
    h.control(0x0F)
    assert h.status & MASK == FAULT  # no edge on bit 7
    h.control(0x8F)
    assert h.status & MASK == SOD
    assert h.drive.device_control.transition == 15
    h.control(0x0F)
    assert h.status & MASK == SOD  # bit 7 falling: nothing; the host must go through shutdown again


def test_stop_3_fault_reaction_passes_through_fault_reaction_active(harness):
    h = harness()
    h.write(0x3025, 6, errors.I2T.mask)  # I2t error -> Stop 3
    h.enable(3)
    h.write(0x60FF, 0, 4096 * 20)
    h.run(0.4)
    h.drive.raise_error(errors.I2T)
    h.run(0.0005)
    assert h.status & MASK == FRA
    h.run_until(lambda: h.status & MASK == FAULT, 2.0)
    assert abs(h.drive.loops.speed) < 1.0


def test_error_inhibit_mask_ignores_the_error(harness):
    h = harness()
    h.write(0x3025, 2, errors.I2T.mask)
    h.enable(3)
    h.drive.raise_error(errors.I2T)
    h.run(0.001)
    assert h.status & MASK == OE
    assert h.events.emergencies == []


def test_brake_timing_delays_operation_enabled(harness):
    from dataclasses import replace

    from servostudio.sim.plant import Plant

    h = harness(plant=replace(Plant.commissioned(), has_brake=True))
    h.write(0x3304, 0, 20)
    h.write(0x3305, 0, 50)
    h.control(0x06)
    h.control(0x07)
    h.control(0x0F, settle=0.00025)
    assert h.status & MASK == SO and h.drive.device_control.power_on
    assert h.read(0x60FE, 1) & 1  # brake still applied
    h.run(0.025)
    assert not h.read(0x60FE, 1) & 1  # released after the drive reaction time
    assert h.status & MASK == SO
    h.run(0.05)
    assert h.status & MASK == OE  # after the brake reaction time
    h.write(0x605C, 0, 0)  # disable operation without a ramp
    h.control(0x07, settle=0.002)
    assert h.read(0x60FE, 1) & 1 and h.drive.physics.brake_engaged
    assert h.drive.device_control.power_on  # held while the brake engages
    h.run(0.06)
    assert not h.drive.device_control.power_on
    assert h.status & MASK == SO
