"""A new simulated drive holds only values it would accept on the bus, so a backup of a fresh drive restores.

Objects whose dictionary entry has a LowLimit above 0 but no DefaultValue start at the limit nearest to zero;
hardware facts (node ID switches, drive ratings, supply class) come from the drive model and its plant.
"""

from __future__ import annotations

import struct
from dataclasses import replace

import pytest

from servostudio.drive.profiles import profile_for
from servostudio.od import builtin_library
from servostudio.od.model import Variable
from servostudio.sim.flash import DRIVEPAR, SAVE
from servostudio.sim.frame import Frame
from servostudio.sim.network import SimulatedNetwork, drive_behaviour_factory
from servostudio.sim.objects import undefined_default

DEVICES = [device for device in builtin_library().devices() if profile_for(device).canopen]  # the CAN simulator's


class Recorder:
    def __init__(self) -> None:
        self.frames: list[Frame] = []

    def receive(self, frame: Frame, timestamp: float) -> None:
        self.frames.append(frame)


def fresh_network(device: str, commissioned: bool) -> SimulatedNetwork:
    factory = None if commissioned else drive_behaviour_factory(seed=7)
    network = SimulatedNetwork("3", device=device, behaviour_factory=factory)
    network.advance(0.01)
    return network


@pytest.mark.parametrize("commissioned", [True, False], ids=["commissioned", "uncommissioned"])
@pytest.mark.parametrize("device", DEVICES)
def test_every_readable_object_of_a_fresh_drive_is_a_value_the_drive_accepts(device, commissioned):
    store = fresh_network(device, commissioned).node(3).store
    refused = []
    for var in store.od.variables():
        if var.index < 0x1000 or not var.access.readable:
            continue
        value = store.read_from_bus(var.index, var.subindex)
        try:
            var.check(value)
        except ValueError as error:
            refused.append(str(error))
    assert refused == []


@pytest.mark.parametrize("device", DEVICES)
def test_a_fresh_drive_loads_back_what_it_saved(device):
    network = fresh_network(device, commissioned=False)
    recorder = Recorder()
    network.attach(recorder)
    network.inject(Frame(0x603, bytes([0x23, 0x10, 0x10, 1]) + struct.pack("<I", SAVE)))
    network.advance(0.3)
    assert [frame.data[0] for frame in recorder.frames if frame.can_id == 0x583] == [0x60]
    flash = network.node(3).flash
    assert flash.read_text(DRIVEPAR)
    assert flash.load(DRIVEPAR), flash.last_error  # what power-on and 'load' do


def _variable(low: int | None, high: int | None) -> Variable:
    var = next(var for var in builtin_library().load("xtrapulspac").variables() if var.key == (0x6510, 5))
    return replace(var, low=low, high=high, default=None)


@pytest.mark.parametrize(("low", "high", "expected"), [(10, 210, 10), (None, None, 0), (0, 5, 0), (-8, -2, -2)])
def test_an_object_without_default_starts_at_the_limit_nearest_to_zero(low, high, expected):
    assert undefined_default(_variable(low, high)) == expected


def test_xtrapulspac_hardware_values_follow_the_node_and_the_plant_and_survive_a_warm_reset():
    network = fresh_network("xtrapulspac", commissioned=True)
    store = network.node(3).store
    assert store.get(0x200A, 1) == 3  # the node ID switches
    assert (store.get(0x6510, 3), store.get(0x6510, 4)) == (230, 230)  # 325 V DC bus: a 230 Vac supply
    assert store.get(0x6510, 5) == 100  # the manual's undervoltage default for 230 Vac
    assert store.get(0x6510, 1) >= store.get(0x6510, 2) > 0
    store.set(0x6510, 5, 150)
    store.restore_defaults()
    assert store.get(0x6510, 5) == 100 and store.get(0x200A, 1) == 3
