"""Regression tests of simulator bugs found by the acceptance tests, run deterministically in virtual time."""

from __future__ import annotations

from servostudio.sim.network import SimulatedNetwork

REV = 4096
TARGET_REACHED = 1 << 10
QUICK_STOP_ACTIVE = 0x07


def test_target_reached_in_quick_stop_active_means_the_stop_has_ended():
    """It used to show the mode's stale flag: set at once while the axis still ran at full speed."""
    network = SimulatedNetwork("1")
    store = network.node(1).store
    write = store.write_from_bus
    write(0x605A, 0, 6)  # quick-stop ramp, then stay in Quick Stop Active
    write(0x6085, 0, 50 * REV)  # 0.2 s from 10 rev/s
    write(0x6060, 0, 3)
    write(0x606D, 0, REV // 4)
    write(0x6083, 0, 200 * REV)
    write(0x60FF, 0, 10 * REV)
    for control_word in (0x06, 0x07, 0x0F):
        write(0x6040, 0, control_word)
        network.advance(0.005)
    network.advance(0.2)
    assert store.read_from_bus(0x6041, 0) & TARGET_REACHED
    write(0x6040, 0, 0x02)
    network.advance(0.05)
    status = store.read_from_bus(0x6041, 0)
    assert status & 0x6F == QUICK_STOP_ACTIVE
    assert abs(store.read_from_bus(0x606C, 0)) > 5 * REV
    assert not status & TARGET_REACHED
    network.advance(0.25)
    status = store.read_from_bus(0x6041, 0)
    assert status & 0x6F == QUICK_STOP_ACTIVE
    assert abs(store.read_from_bus(0x606C, 0)) < REV // 4
    assert status & TARGET_REACHED
