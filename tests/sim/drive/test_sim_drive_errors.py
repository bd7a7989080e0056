"""Drive errors and warnings: following error, speed error, I²t, overcurrent, undervoltage; EMCY and fault reset."""

from __future__ import annotations

from dataclasses import replace

from servostudio.sim.plant import Plant

REV = 4096
FAULT = 0x08


def test_position_following_error_raises_bits_code_emcy_and_resets(harness):
    h = harness()
    h.write(0x6065, 0, 50)  # following error window: 50 increments
    h.write(0x60FB, 3, 0)  # no speed feed-forward: the axis lags
    h.write(0x60FB, 4, 0)
    h.write(0x6081, 0, REV * 20)
    h.write(0x6083, 0, REV * 500)
    h.write(0x6084, 0, REV * 500)
    h.enable(1)
    h.write(0x607A, 0, h.read(0x6064) + REV * 10)
    h.control(0x1F)
    h.run_until(lambda: h.status & 0x0F == FAULT, 1.0)
    assert h.read(0x3022, 2) == 1 << 2  # code 35 = word 2 bit 2
    assert h.read(0x3022, 1) == 0
    assert h.read(0x603F) == 0x8611
    assert h.read(0x3023, 4) == 35
    assert h.events.emergencies == [(0x8611, 35, b"")]
    assert not h.drive.device_control.power_on  # Stop 0 by default
    h.control(0x0F)
    h.control(0x8F)
    assert h.status & 0x4F == 0x40
    assert h.read(0x3022, 2) == 0
    assert h.read(0x603F) == 0
    assert h.events.cleared == 1


def test_following_error_time_out_0x6066_delays_the_error(harness):
    """encoTRive (it has 0x6066): an axis pushed against a hard stop faults only after the time-out."""
    plant = replace(Plant.commissioned(), positive_hard_stop=0.5, positive_limit_switch=None)
    h = harness("encotrive", plant=plant)
    h.write(0x6065, 0, 50)
    h.write(0x6066, 0, 300)
    h.write(0x6081, 0, 600)  # rpm
    h.write(0x6083, 0, 6000)
    h.write(0x6084, 0, 6000)
    h.enable(1)
    h.write(0x607A, 0, REV * 3)
    h.control(0x1F)
    h.run_until(lambda: abs(h.read(0x6062) - h.read(0x6064)) > 60, 1.0, step=0.001)
    h.run(0.25)
    assert h.status & 0x0F != FAULT
    h.run_until(lambda: h.status & 0x0F == FAULT, 0.1, step=0.001)
    assert h.read(0x603F) == 0x8611


def test_speed_following_error(harness):
    h = harness()
    h.write(0x306D, 0, REV * 2)  # 2 rev/s
    h.write(0x6073, 0, 200)  # weak current limit: the speed lags the ramp
    h.write(0x6083, 0, REV * 1000)
    h.enable(3)
    h.write(0x60FF, 0, REV * 40)
    h.run_until(lambda: h.status & 0x0F == FAULT, 1.0)
    assert h.read(0x3022, 2) == 1 << 1  # code 34
    assert h.events.emergencies[0][:2] == (0x8400, 34)


def blocked_axis(harness, i2t_mode: int):
    plant = replace(Plant.commissioned(), positive_hard_stop=0.05, positive_limit_switch=None)
    h = harness(plant=plant)
    h.write(0x3404, 1, i2t_mode)
    h.write(0x6087, 0, 10_000_000)
    h.enable(4)
    h.write(0x6071, 0, 3000)  # 3 × rated = the max current, against the stop
    return h, plant


def test_i2t_fusing_warns_limits_then_errors(harness):
    h, plant = blocked_axis(harness, i2t_mode=1)
    rated = plant.stall_current
    # locked shaft: E_lim = 4 s·Ir², i = 3·Ir -> limitation after 4/8 = 0.5 s, warning at 0.425 s
    h.run(0.40)
    assert not h.read(0x3024) & (1 << 18)
    h.run(0.06)
    assert h.read(0x3024) & (1 << 18)
    assert h.status & 0x80
    h.run(0.1)
    assert abs(h.drive.physics.i_q) < rated * 1.05  # limited to the rated current
    h.run_until(lambda: h.status & 0x0F == FAULT, 1.2)
    assert h.read(0x3022, 2) == 1 << 5  # code 38
    assert h.events.emergencies[-1][:2] == (0x2350, 38)


def test_i2t_limiting_mode_never_errors(harness):
    h, plant = blocked_axis(harness, i2t_mode=0)
    h.run(2.5)
    assert h.status & 0x0F != FAULT
    assert h.read(0x3024) & (1 << 18)
    assert abs(h.drive.physics.i_q) < plant.stall_current * 1.05


def test_too_high_current_gains_trip_overcurrent(harness):
    # a low-inductance motor: the unstable current loop swings far beyond the trip level
    h = harness(plant=replace(Plant.commissioned(), inductance=1e-3))
    h.write(0x60F6, 2, h.read(0x60F6, 2) * 4)
    h.write(0x60F6, 4, h.read(0x60F6, 4) * 4)
    h.enable(3)
    h.write(0x60FF, 0, REV * 5)
    h.run_until(lambda: h.status & 0x0F == FAULT, 0.5)
    assert h.read(0x3022, 1) == 1 << 17  # code 18
    assert h.events.emergencies[0][:2] == (0x2310, 18)


def test_undervoltage_when_the_mains_are_off(harness):
    h = harness(plant=replace(Plant.commissioned(), mains_on=False))
    h.write(0x6510, 5, 100)
    h.control(0x06)
    h.control(0x07)
    h.control(0x0F)
    assert h.status & 0x0F == FAULT
    assert h.read(0x3022, 1) == 1 << 2  # code 3
    h.control(0x8F)
    assert h.status & 0x0F == FAULT  # the cause is still there: no reset


def test_fault_injection_entry_point(harness):
    h = harness()
    h.drive.raise_error(51)
    h.run(0.001)
    assert h.read(0x3022, 2) == 1 << 18
    assert h.events.emergencies == [(0x8130, 51, b"")]


def test_software_position_limit_on_a_linear_axis(harness):
    h = harness()
    h.write(0x3360, 0, 1)
    start = h.read(0x6064)
    h.write(0x607D, 1, start - REV)
    h.write(0x607D, 2, start + REV)
    h.write(0x6083, 0, REV * 50)
    h.enable(3)
    h.write(0x60FF, 0, REV * 2)
    h.run_until(lambda: h.status & 0x0F == FAULT, 2.0)
    assert h.read(0x3022, 2) == 1 << 3  # code 36
    assert h.events.emergencies[0][:2] == (0x8680, 36)


def test_digital_motor_temperature_probe_warns_then_errors(harness):
    h = harness()
    h.write(0x3324, 1, 2)
    h.write(0x3324, 4, 20)  # below the ambient 25 °C: warning at once
    h.write(0x3324, 5, 200)
    h.run(0.01)
    assert h.read(0x3024) & (1 << 21)
    assert h.status & 0x0F != FAULT
    h.write(0x3324, 5, 24)
    h.run(0.01)
    assert h.read(0x3022, 2) == 1 << 4  # code 37


def test_inhibit_input_stops_with_0x305a_and_refuses_enable(harness):
    h = harness()
    h.write(0x305A, 0, 2)
    h.write(0x6085, 0, REV * 100)
    h.write(0x6083, 0, REV * 100)
    h.enable(3)
    h.write(0x60FF, 0, REV * 10)
    h.run(0.2)
    h.drive.set_inhibit(True)
    h.run(0.001)
    assert h.drive.device_control.power_on  # ramping down on the quick-stop ramp
    h.run_until(lambda: h.status & 0x4F == 0x40, 1.0)
    h.control(0x06)
    h.control(0x07)
    h.control(0x0F)
    assert h.status & 0x6F == 0x23  # enable refused while inhibited
    h.drive.set_inhibit(False)
    h.control(0x07)
    h.control(0x0F)
    assert h.status & 0x6F == 0x27
