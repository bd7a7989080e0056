"""Commissioned vs factory start, warm reset, and a few objects that shape the loops."""

from __future__ import annotations

from dataclasses import replace

import pytest

from servostudio.sim.drive import gains
from servostudio.sim.drive.commissioning import COMMISSIONING_BANDWIDTH_HZ
from servostudio.sim.plant import Plant

REV = 4096


def test_commissioned_drive_holds_the_plants_true_values(harness):
    plant = Plant.commissioned()
    h = harness()
    assert [h.read(0x3410, s) for s in (1, 2, 3)] == [plant.pole_pairs, plant.phase_order, plant.sensor_offset]
    assert h.read(0x6410, 11) == round(plant.torque_constant * 1000)
    assert h.read(0x6410, 12) == round(plant.motor_inertia * 1e6)
    assert h.read(0x6075) == round(plant.stall_current * 1000)
    expected = gains.tuned_gains(
        plant.total_inertia, plant.torque_constant, COMMISSIONING_BANDWIDTH_HZ, viscous_friction=plant.viscous_friction
    )
    assert h.read(0x60F9, 2) == expected.kpv
    assert h.read(0x60FB, 2) == expected.kpp


def test_factory_drive_knows_nothing_about_the_plant(harness):
    plant = Plant.from_seed(9)
    h = harness(plant=plant, commissioned=False)
    od = h.store.od
    for address in ((0x3410, 3), (0x60F9, 2), (0x60F6, 2), (0x6075, 0)):
        default = od[address].default_for(h.store.node_id)
        assert h.read(*address) == (default if default is not None else 0)


def test_commissioning_does_not_overwrite_loaded_parameters(harness):
    from servostudio.od import builtin_library
    from servostudio.sim.drive import make_behaviour
    from servostudio.sim.objects import ObjectStore

    h = harness()
    store = ObjectStore(builtin_library().load("xtrapulspac"), 3)
    store.set(0x60F9, 2, 1234)  # as if DRIVEPAR.TXT had been loaded
    make_behaviour("xtrapulspac", store, Plant.commissioned(), h.events, True)
    assert store.get(0x60F9, 2) == 1234
    assert store.get(0x3410, 1) == Plant.commissioned().pole_pairs


def test_warm_reset_restarts_disabled_without_faults(harness):
    h = harness()
    h.enable(3)
    h.drive.raise_error(35)
    h.run(0.002)
    assert h.status & 0x0F == 0x08
    h.drive.on_nmt_reset()
    h.run(0.002)
    assert h.status == 0x0240
    assert h.read(0x3022, 2) == 0


def test_dynamic_current_limit_scales_the_torque(harness):
    plant = replace(Plant.commissioned(), positive_hard_stop=None, positive_limit_switch=None, home_switch=None)
    h = harness(plant=plant)
    h.write(0x30D1, 0, 0x3FFF // 4)
    h.write(0x6073, 0, 1000)  # max = rated 3 A, a quarter of it is 0.75 A
    h.write(0x6083, 0, 0xFFFFFFF)
    h.enable(3)
    h.write(0x60FF, 0, REV * 50)
    h.run(0.05)
    assert h.drive.physics.i_q == pytest.approx(0.75, rel=0.03)
    assert h.read(0x6078) == pytest.approx(250, abs=10)  # ‰ of the rated current


def test_status_word_bit_8_follows_a_linked_object_bit(harness):
    h = harness()
    h.write(0x3044, 1, 0x60FD0002)  # bit 8 <- home switch (0x60FD bit 2)
    h.run(0.01)
    assert not h.status & 0x100
    moved = harness(plant=replace(Plant.commissioned(), initial_position=4.0))
    moved.write(0x3044, 1, 0x60FD0002)
    moved.run(0.01)
    assert moved.status & 0x100


def test_torque_offset_adds_current(harness):
    h = harness(plant=replace(Plant.commissioned(), positive_hard_stop=0.01, positive_limit_switch=None))
    h.write(0x6087, 0, 10_000_000)
    h.write(0x60B2, 0, 200)  # +20 % of the rated current
    h.enable(4)
    h.run(0.02)
    assert h.drive.physics.i_q == pytest.approx(0.2 * 3.0, rel=0.05)
