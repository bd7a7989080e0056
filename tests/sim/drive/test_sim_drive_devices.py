"""CD1-k and encoTRive on the shared engine: their addresses, units, procedures and error reporting."""

from __future__ import annotations

import pytest

from servostudio.sim.drive import make_behaviour
from servostudio.sim.drive.procedures import signature
from servostudio.sim.plant import Plant


def test_unknown_device_is_refused(harness):
    h = harness()
    with pytest.raises(ValueError, match="no simulated behaviour for device 'ttapro'"):
        make_behaviour("ttapro", h.store, Plant.commissioned(), h.events, True)


def test_cd1k_runs_in_increments_with_default_mode_ip(harness):
    h = harness("cd1k")
    h.run(0.001)
    assert h.read(0x6061) == 7  # ip is the CD1-k default
    assert h.status == 0x0240
    h.write(0x6083, 0, 65536 * 20)
    h.enable(3)
    h.write(0x60FF, 0, 65536 * 2)  # 2 rev/s with the resolver's 65536 increments per revolution
    h.run(0.3)
    assert h.read(0x606C) == pytest.approx(65536 * 2, rel=0.02)


def test_cd1k_commutation_lives_in_0x6410_and_auto_phasing_on_0x3410(harness):
    plant = Plant.from_seed(31)
    h = harness("cd1k", plant=plant, commissioned=False)
    h.write(0x60F6, 1, 1500)  # q/d current gains by hand (the CD1-k has no 'calc')
    h.write(0x60F6, 2, 1200)
    h.write(0x60F6, 3, 1500)
    h.write(0x60F6, 4, 1200)
    h.write(0x3410, 0, signature("apha"))
    h.run(0.001)
    assert h.status & (1 << 15)
    h.run_until(lambda: h.read(0x3410) != 2, 20.0, step=0.05)
    assert h.read(0x3410) == 5
    assert h.read(0x6410, 2) == plant.pole_pairs
    assert h.read(0x6410, 3) == (0 if plant.phase_order == 0x5555 else 1)
    difference = (h.read(0x6410, 4) - plant.sensor_offset) % 65536
    assert min(difference, 65536 - difference) < 400


def test_cd1k_reports_errors_in_the_0x3020_bit_field(harness):
    h = harness("cd1k")
    h.enable(3)
    h.drive.raise_error(35)  # following error
    h.run(0.001)
    assert h.status & 0x0F == 0x08
    assert h.read(0x3020) == 1 << 3
    assert h.events.emergencies == [(0x8611, 0x08, b"\x00\x00\x00")]


def test_cd1k_fault_reaction_mask_selects_stop_3(harness):
    h = harness("cd1k")
    h.write(0x3331, 0, 1 << 3)
    h.write(0x6083, 0, 65536 * 50)
    h.enable(3)
    h.write(0x60FF, 0, 65536 * 5)
    h.run(0.3)
    h.drive.raise_error(35)
    h.run(0.0005)
    assert h.status & 0x0F == 0x0F  # fault reaction active while stopping at the current limit
    h.run_until(lambda: h.status & 0x0F == 0x08, 1.0)


def test_encotrive_profile_velocity_in_rpm_and_position_preset(harness):
    h = harness("encotrive")
    h.write(0x6083, 0, 6000)  # rpm/s
    h.write(0x6084, 0, 6000)
    h.enable(3)
    h.write(0x60FF, 0, 600)  # rpm
    h.run(0.4)
    assert h.read(0x606C) == pytest.approx(600, abs=6)
    h.write(0x60FF, 0, 0)
    h.run(0.3)
    h.write(0x6064, 0, 12345)  # absolute position preset
    h.run(0.001)
    assert h.read(0x6064) == pytest.approx(12345, abs=2)


def test_encotrive_profile_position_move(harness):
    h = harness("encotrive")
    h.write(0x6081, 0, 1200)  # rpm
    h.write(0x6083, 0, 12000)
    h.write(0x6084, 0, 12000)
    h.write(0x6067, 0, 10)
    h.write(0x6068, 0, 5)
    h.enable(1)
    start = h.read(0x6064)
    h.write(0x607A, 0, start + 4096 * 3)
    h.control(0x1F)
    h.control(0x0F)
    h.run_until(lambda: h.status & 0x400, 2.0)
    assert abs(h.read(0x6064) - (start + 4096 * 3)) <= 10


def test_encotrive_has_no_homing_and_rejects_the_mode(harness):
    h = harness("encotrive")
    assert (0x6098, 0) not in h.store
    h.write(0x6060, 0, 6)
    h.control(0x06)
    h.control(0x07)
    h.control(0x0F)
    h.run(0.05)
    assert h.drive.loops.position_ref == pytest.approx(h.drive.loops.position, abs=0.01)  # holds, no motion


def test_encotrive_following_error_emcy_has_no_infranor_byte(harness):
    h = harness("encotrive")
    h.enable(3)
    h.drive.raise_error(35)
    h.run(0.001)
    assert h.read(0x603F) == 0x8611
    assert h.events.emergencies == [(0x8611, 0, b"")]
