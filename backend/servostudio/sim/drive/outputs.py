"""The XtrapulsPac's logic outputs (manual §3.2.5.1: "any bit of any object can drive a physical output").

OUTn takes the bit its source 0x3054,n names (``index << 16 | sub << 8 | bit``), inverted by 0x3055 bit n−1, and
shows in 0x60FE,1 bit 15+n (OUT1..OUT3 wired, OUT4..OUT6 virtual), in 0x3058,2 (the upper half of 0x60FE,1) and,
for OUT4..OUT6, in 0x3059,2 bits 3–5. An output without a source (0) is the bus's, written through 0x60FE,1, and
its polarity is left to the wiring *(decision, docs/io.md)*. Refreshed with the drive's slow measurements; the
virtual links 0x3059,3 are not modelled.
"""

from __future__ import annotations

from servostudio.sim.objects import ObjectStore

SOURCES, POLARITY = 0x3054, (0x3055, 0)
OUTPUTS_16, VIRTUAL_OUTPUTS = (0x3058, 2), (0x3059, 2)
COUNT, FIRST_BIT = 6, 16
VIRTUAL_SHIFT = 3  # OUT4 → 0x3059,2 bit 3


class LogicOutputs:
    def __init__(self, store: ObjectStore) -> None:
        self.store = store
        self.present = (SOURCES, 1) in store and POLARITY in store

    def routed(self) -> tuple[int, int]:
        """(the 0x60FE,1 bits the sources drive, their mask)."""
        if not self.present:
            return 0, 0
        store = self.store
        polarity = int(store.get(*POLARITY))
        bits = mask = 0
        for number in range(1, COUNT + 1):
            source = int(store.get(SOURCES, number))
            if source:
                level = self._bit(source) ^ (polarity >> (number - 1) & 1)
                mask |= 1 << (FIRST_BIT + number - 1)
                bits |= level << (FIRST_BIT + number - 1)
        return bits, mask

    def show(self, outputs: int) -> None:
        """The images of 0x60FE,1: its upper half and the virtual outputs."""
        store = self.store
        if OUTPUTS_16 in store:
            store.set(*OUTPUTS_16, outputs >> FIRST_BIT & 0xFFFF)
        if VIRTUAL_OUTPUTS in store:
            store.set(*VIRTUAL_OUTPUTS, (outputs >> (FIRST_BIT + 3) & 0x7) << VIRTUAL_SHIFT)

    def _bit(self, pointer: int) -> int:
        key = (pointer >> 16 & 0xFFFF, pointer >> 8 & 0xFF)
        value = self.store.get(*key) if key in self.store else 0
        return int(value) >> (pointer & 0x1F) & 1 if isinstance(value, int) else 0
