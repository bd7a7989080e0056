"""Sequence memory of the XtrapulsPac (RAM behind 0x3610 / 0x3611) and its flash file SEQUENCE.TXT.

0x3610 selects a sequence number (0 .. 0x3612−1, else abort 0x06090031/0x06090032); reads and writes of 0x3611
subs 1..26 then address that sequence's record. `records` holds the non-empty slots; the drive model reads a
sequence with `record(number)`. SEQUENCE.TXT conversion uses `servostudio.formats` (the same definitions as the
tool), so a table written by `sseq` reads back equal.
"""

from __future__ import annotations

from servostudio.formats.sequence_model import LoadMode, Sequence, SequenceTable
from servostudio.formats.sequence_spec import MAX_SEQUENCES, SEQUENCE_NUMBER_INDEX, SEQUENCE_PARAMETERS_INDEX
from servostudio.od.model import Value
from servostudio.sim import sdo_abort
from servostudio.sim.objects import ObjectStore
from servostudio.sim.sdo_abort import SdoAbort

MAXIMUM_SEQUENCES = 0x3612


class SequenceMemory:
    def __init__(self, store: ObjectStore) -> None:
        self.store = store
        self.records: dict[int, dict[int, int]] = {}
        subs = store.od.object(SEQUENCE_PARAMETERS_INDEX).subs
        self._defaults = {sub: int(store.get(SEQUENCE_PARAMETERS_INDEX, sub)) for sub in subs if sub}
        store.on_write(SEQUENCE_NUMBER_INDEX, 0, self._select)
        store.on_write(SEQUENCE_PARAMETERS_INDEX, None, self._write)
        store.on_read(SEQUENCE_PARAMETERS_INDEX, None, self._read)

    @classmethod
    def for_store(cls, store: ObjectStore) -> SequenceMemory | None:
        """A memory when the device has the sequence objects, else None."""
        if (SEQUENCE_NUMBER_INDEX, 0) in store and (SEQUENCE_PARAMETERS_INDEX, 1) in store:
            return cls(store)
        return None

    @property
    def capacity(self) -> int:
        if (MAXIMUM_SEQUENCES, 0) in self.store:
            return min(int(self.store.get(MAXIMUM_SEQUENCES, 0)), MAX_SEQUENCES)
        return MAX_SEQUENCES

    @property
    def selected(self) -> int:
        return int(self.store.get(SEQUENCE_NUMBER_INDEX, 0))

    def record(self, number: int) -> dict[int, int]:
        """All subs 1..26 of one sequence (defaults for an empty slot: type 0)."""
        return {**self._defaults, **self.records.get(number, {})}

    # -- object access --------------------------------------------------------------------------------------------

    def _select(self, index: int, sub: int, value: Value) -> None:
        number = int(value)
        if number < 0:
            raise SdoAbort(sdo_abort.VALUE_TOO_LOW, f"sequence number {number} < 0")
        if number >= self.capacity:
            raise SdoAbort(sdo_abort.VALUE_TOO_HIGH, f"sequence number {number} >= {self.capacity}")

    def _write(self, index: int, sub: int, value: Value) -> None:
        record = self.record(self.selected)
        record[sub] = int(value)
        self.records[self.selected] = record

    def _read(self, index: int, sub: int) -> Value:
        if sub == 0:
            return self.store.get(index, 0)
        return self.record(self.selected)[sub]

    # -- tables ---------------------------------------------------------------------------------------------------

    def table(self) -> SequenceTable:
        """The memory as a table; ValueError when a slot holds what SEQUENCE.TXT cannot express."""
        sequences = {}
        for number in sorted(self.records):
            sequence = Sequence.from_object_values(self.records[number])
            if sequence is not None:
                sequences[number] = sequence
        return SequenceTable(sequences)

    def take(self, table: SequenceTable, mode: LoadMode) -> None:
        """lseq (LOAD: clears every other slot) or mseq (MERGE: keeps them)."""
        if any(number >= self.capacity for number in table):
            raise ValueError(f"sequence numbers must be below {self.capacity}")
        kept = {} if mode is LoadMode.LOAD else {n: r for n, r in self.records.items() if n not in table.sequences}
        self.records = {**kept, **{number: table[number].to_object_values() for number in table}}
