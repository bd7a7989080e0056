"""The simulated drives act on their input configuration (docs/io.md): an XtrapulsPac logic input routed to a limit
switch function blocks that direction while it is active after its polarity; a CD1-k limit switch input blocks its
direction only while 0x30FD keeps its dedicated function; the plant's own switches keep working; an XtrapulsPac
output shows the bit its source names, through its polarity."""

from __future__ import annotations

from dataclasses import replace

from tests.support.drive_harness import NODE_ID, EventRecorder, Harness

from servostudio.od import builtin_library
from servostudio.sim.drive import make_behaviour
from servostudio.sim.objects import ObjectStore
from servostudio.sim.plant import Plant
from servostudio.sim.sequences import SequenceMemory
from servostudio.sim.simulator_objects import with_simulator_objects

REV = 4096
WIRING = 0x5F00
POSITIVE_LIMIT = 0x60FD0001
INHIBIT = 0x60FD0003


class WiredHarness(Harness):
    """The harness on the simulated node's dictionary (with 0x5F00) and, on the XtrapulsPac, its sequence memory,
    which owns the logic inputs."""

    def __init__(self, device: str, plant: Plant | None = None) -> None:
        self.store = ObjectStore(with_simulator_objects(builtin_library().load(device)), NODE_ID)
        self.events = EventRecorder()
        self.events.sequences = SequenceMemory.for_store(self.store)  # type: ignore[attr-defined]
        self.plant = plant or Plant.commissioned()
        self.drive = make_behaviour(device, self.store, self.plant, self.events, True)


def speed_mode(h: Harness, speed: int) -> None:
    """Profile velocity at ``speed`` user units per second from standstill."""
    h.write(0x6083, 0, REV * 100)
    h.write(0x6084, 0, REV * 100)
    h.enable(3)
    h.write(0x60FF, 0, speed)
    h.run(0.3)


def moved(h: Harness, seconds: float) -> float:
    before = int(h.read(0x6064))
    h.run(seconds)
    return (int(h.read(0x6064)) - before) / REV


def test_xtrapulspac_input_configured_as_inverted_positive_limit_blocks_positive_motion():
    h = WiredHarness("xtrapulspac")
    h.write(0x3050, 3, POSITIVE_LIMIT)  # IN3 → positive limit switch
    h.write(0x3051, 0, 0b100)  # IN3 inverted: active without 24 V (a normally closed switch)
    h.run(0.01)
    assert int(h.read(0x60FD)) & 0b11 == 0b10
    speed_mode(h, 2 * REV)
    assert abs(moved(h, 0.2)) < 0.01  # the limit holds the axis
    h.write(0x60FF, 0, -2 * REV)
    assert moved(h, 0.3) < -0.2  # the other direction is free
    h.write(WIRING, 0, 0b100)  # 24 V on IN3: the switch is closed, the limit released
    h.write(0x60FF, 0, 2 * REV)
    h.run(0.2)
    assert int(h.read(0x60FD)) & 0b10 == 0 and moved(h, 0.2) > 0.2


def test_xtrapulspac_polarity_decides_when_the_limit_is_active():
    h = WiredHarness("xtrapulspac")
    h.write(0x3050, 1, POSITIVE_LIMIT)
    h.run(0.01)
    assert int(h.read(0x60FD)) & 0b10 == 0  # normal polarity, no 24 V: inactive
    h.write(WIRING, 0, 0b1)
    h.run(0.01)
    assert int(h.read(0x60FD)) & 0b10 == 0b10 and int(h.read(0x3024)) & 1 << 16  # the limit switch warning
    h.write(0x3050, 1, 0)  # no function: the input only shows in 0x60FD bit 16
    h.run(0.01)
    assert int(h.read(0x60FD)) & 0xFFFF == 0 and int(h.read(0x60FD)) >> 16 & 1


def test_xtrapulspac_input_configured_as_inhibit_refuses_enable():
    h = WiredHarness("xtrapulspac")
    h.write(0x3050, 2, INHIBIT)
    h.write(0x3051, 0, 0b10)  # losing 24 V inhibits the drive (the manual's ENABLE example)
    h.run(0.01)
    h.control(0x06)
    h.control(0x07)
    h.control(0x0F)
    assert h.status & 0x6F == 0x23
    h.write(WIRING, 0, 0b10)
    h.run(0.01)
    h.enable()


def test_cd1k_limit_switch_input_acts_only_while_dedicated():
    h = WiredHarness("cd1k")
    h.write(WIRING, 0, 0b1)  # LS+ active
    h.run(0.01)
    assert int(h.read(0x60FD)) & 0b10 and int(h.read(0x60FD)) >> 16 & 1
    speed_mode(h, 2 * REV)
    assert abs(moved(h, 0.2)) < 0.01
    h.write(0x30FD, 0, 0x3F & ~0b1)  # LS+ freed for general use
    h.run(0.2)
    assert int(h.read(0x60FD)) & 0b10 == 0 and int(h.read(0x60FD)) >> 16 & 1
    assert moved(h, 0.2) > 0.2


def test_cd1k_plant_limit_switch_is_wired_to_its_input():
    plant = Plant.commissioned()
    assert plant.positive_limit_switch is not None
    h = WiredHarness("cd1k", replace(plant, initial_position=plant.positive_limit_switch + 0.2))
    h.run(0.01)
    assert int(h.read(0x60FD)) & 0b10 and int(h.read(0x60FD)) >> 16 & 1
    h.write(0x30FD, 0, 0x3E)
    h.run(0.01)
    assert int(h.read(0x60FD)) & 0b10 == 0


def test_xtrapulspac_output_follows_its_source_bit_and_polarity():
    h = WiredHarness("xtrapulspac")
    h.write(0x3054, 1, 0x60410002)  # OUT1 ← status word bit 2 (operation enabled)
    h.write(0x3054, 4, 0x60410002)  # OUT4 (virtual) too, inverted
    h.write(0x3055, 0, 0b1000)
    h.run(0.05)
    assert int(h.read(0x60FE, 1)) >> 16 & 0b1001 == 0b1000
    h.enable(3)
    h.run(0.05)
    assert int(h.read(0x60FE, 1)) >> 16 & 0b1001 == 0b0001
    assert int(h.read(0x3058, 2)) & 0b1001 == 0b0001 and int(h.read(0x3059, 2)) == 0


def test_an_output_without_source_is_the_buses():
    h = WiredHarness("xtrapulspac")
    h.write(0x60FE, 1, 1 << 17)  # OUT2 set by the bus
    h.run(0.05)
    assert int(h.read(0x60FE, 1)) & 1 << 17


def test_homing_finds_the_home_switch_an_input_is_configured_as():
    """A plant without a home switch of its own: IN3 routed to the home function is the switch homing looks for; its
    edge (24 V taken away on the test bench 0x5F00) ends the run, as the edge of a real cam would."""
    h = WiredHarness("xtrapulspac", replace(Plant.commissioned(), home_switch=None))
    h.write(0x3050, 3, 0x60FD0002)  # IN3 → home switch
    h.write(WIRING, 0, 0b100)  # 24 V on IN3: the cam is under the sensor
    h.write(0x6098, 0, 19)  # home switch, no index
    h.write(0x6099, 1, REV * 2)
    h.write(0x6099, 2, REV // 2)
    h.write(0x609A, 0, REV * 200)
    h.enable(6)
    h.control(0x1F)
    h.run(0.2)
    assert h.status & 0x3400 == 0  # still homing: the switch has not changed
    h.write(WIRING, 0, 0)  # the edge
    h.run_until(lambda: h.status & 0x3400 in (0x1400, 0x2400, 0x2000), 3.0)
    assert h.status & 0x3400 == 0x1400, f"homing did not end on the configured input: status {h.status:#06x}"


def test_an_input_configured_as_reset_clears_a_fault_on_its_rising_edge():
    h = WiredHarness("xtrapulspac")
    h.write(0x3050, 4, 0x60FD000C)  # IN4 → RESET (0x60FD bit 12)
    h.run(0.01)
    h.drive.raise_error(35)  # a following error whose cause has gone (the fault-injection entry)
    h.run(0.01)
    assert h.status & 0x08  # fault
    h.write(WIRING, 0, 0b1000)  # 24 V on IN4: the rising edge
    h.run(0.01)
    assert not h.status & 0x08 and h.status & 0x4F == 0x40  # switch on disabled, fault reset
    assert int(h.read(0x60FD)) & 1 << 12


def test_an_input_configured_as_quick_stop_stops_the_axis_and_keeps_it_from_enabling():
    h = WiredHarness("xtrapulspac")
    h.write(0x3050, 5, 0x60FD000F)  # IN5 → QUICK STOP (0x60FD bit 15)
    speed_mode(h, 2 * REV)
    assert moved(h, 0.1) > 0.1
    h.write(WIRING, 0, 0b10000)  # 24 V on IN5
    h.run(0.3)
    assert h.status & 0x6F != 0x27 and abs(moved(h, 0.1)) < 0.01  # quick-stopped, standing
    h.control(0x06)
    h.control(0x07)
    h.control(0x0F, settle=0.01)
    assert h.status & 0x6F != 0x27  # not enabled while the input is active
    h.write(WIRING, 0, 0)
    h.enable()
    assert h.status & 0x6F == 0x27
