"""The XtrapulsPac's logic inputs as far as the sequencer needs them (manual §3.2.5.1, L12755–13228): "any physical
input can be copied into any bit of any object".

IN1..IN5 are the simulator-only object 0x5F00 (the test bench's wiring, docs/simulator.md) and IN6..IN10 the
virtual inputs 0x3059,1 bits 5–9. Through the polarity 0x3051 (bit n−1 inverts INn) they show in 0x60FD bits
16–25 and 0x3058,1, the raw IN1..IN5 in 0x3058,3, and each input is copied into the bit its destination 0x3050,n
names (index << 16 | sub << 8 | bit): 0x3050,1 = 0x36010307 puts IN1 on bit 7 of the conditional input 0x3601,3
("logic input 8" of the manual's conditional jump), 0x60400004 on the START bit of the control word.

The copy is made whenever an input, the polarity or a destination is written (and at power-on), not every
period: idle inputs cost nothing. A bus write to a destination bit therefore holds until the input next changes.
A destination among the input functions of 0x60FD (bits 0–15: limit switches, home, INHIBIT, …) is not copied
into the object but handed to the drive (``DriveBehaviour.routed_inputs``), which ORs it with the plant's own
switches and acts on it: an input configured as the positive limit switch blocks positive motion while it is
active after its polarity (docs/io.md). Not modelled here: the virtual links 0x3059,3.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from servostudio.od.model import Value, Variable
from servostudio.sim.simulator_objects import PHYSICAL_INPUTS

if TYPE_CHECKING:
    from servostudio.sim.drive.behaviour import DriveBehaviour

DESTINATIONS = 0x3050
POLARITY = (0x3051, 0)
INPUTS_16, PHYSICAL_INPUTS_16 = (0x3058, 1), (0x3058, 3)
VIRTUAL_INPUTS = (0x3059, 1)
WIRING = (PHYSICAL_INPUTS, 0)
INPUT_COUNT = 10
PHYSICAL_MASK = 0x001F
VIRTUAL_MASK = 0x03E0
DIGITAL_INPUTS_SHIFT = 16
FUNCTIONS_INDEX = 0x60FD  # a destination 0x60FD00bb (bb < 16) gives the input function bb


class LogicInputs:
    def __init__(self, drive: DriveBehaviour) -> None:
        self.drive = drive
        self.store = store = drive.store
        for key in (WIRING, POLARITY, VIRTUAL_INPUTS):
            if key in store:
                store.on_write(*key, self._written)
        store.on_write(DESTINATIONS, None, self._written)
        self.apply()

    def _written(self, index: int, sub: int, value: Value) -> None:
        """Take the new value before it is stored, then copy the inputs again. The wiring is hardware: it is kept
        through a warm reset."""
        if (index, sub) == WIRING:
            self.store.set_factory(index, sub, value)
        else:
            self.store.set(index, sub, value)
        self.apply()

    def levels(self) -> int:
        """IN1..IN10 as bits 0–9, after the polarity."""
        raw = self._value(WIRING) & PHYSICAL_MASK | self._value(VIRTUAL_INPUTS) & VIRTUAL_MASK
        return raw ^ self._value(POLARITY) & (PHYSICAL_MASK | VIRTUAL_MASK)

    def apply(self) -> None:
        levels = self.levels()
        store = self.store
        store.set(*PHYSICAL_INPUTS_16, self._value(WIRING) & PHYSICAL_MASK)
        store.set(*INPUTS_16, levels)
        drive = self.drive
        kept = int(drive.live("digital_inputs")) & ~((PHYSICAL_MASK | VIRTUAL_MASK) << DIGITAL_INPUTS_SHIFT)
        drive.write("digital_inputs", kept | levels << DIGITAL_INPUTS_SHIFT)
        functions = 0
        for number in range(1, INPUT_COUNT + 1):
            pointer, level = int(store.get(DESTINATIONS, number)), levels >> (number - 1) & 1
            if pointer >> 16 == FUNCTIONS_INDEX and pointer & 0xFF00 == 0 and pointer & 0xFF < 16:
                functions |= level << (pointer & 0xFF)
            else:
                self._copy(pointer, level)
        drive.routed_inputs = functions
        drive.parameters_changed()  # a destination may be a parameter the drive took a snapshot of

    def _copy(self, pointer: int, level: int) -> None:
        variable = self.store.od.get(pointer >> 16 & 0xFFFF, pointer >> 8 & 0xFF) if pointer else None
        if variable is None or not variable.data_type.is_integer:
            return
        value = with_bit(variable, int(self.store.get(*variable.key)), pointer & 0x1F, level)
        self.store.set(variable.index, variable.subindex, value)

    def _value(self, key: tuple[int, int]) -> int:
        return int(self.store.get(*key)) if key in self.store else 0


def with_bit(variable: Variable, value: int, bit: int, level: int) -> int:
    """`value` with `bit` set to `level`, kept in the object's type (bit 15 of an I16 makes it negative)."""
    width = variable.data_type.fixed_size * 8
    raw = (value & ~(1 << bit) | level << bit) & ((1 << width) - 1)
    if variable.data_type.is_signed and raw >> (width - 1):
        return raw - (1 << width)
    return raw
