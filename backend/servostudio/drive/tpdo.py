"""A node's transmit PDOs as a capture borrows them (CiA 301: communication 0x1800+n, mapping 0x1A00+n).

What the dictionary offers (`tpdo_slots`), the present configuration read (`read_tpdo`), a synchronous mapping
written in the order CiA 301 asks of a master — COB-ID invalid, mapping count 0, the entries, the count, the
transmission type, COB-ID valid — and the saved configuration written back the same way (`write_tpdo`).
"""

from __future__ import annotations

from dataclasses import dataclass

from servostudio.drive.access import Drive
from servostudio.od.model import ObjectDictionary, Variable

TPDO_COMMUNICATION, TPDO_MAPPING = 0x1800, 0x1A00
TPDO_LIMIT = 512
COB_ID_INVALID = 0x80000000
COB_ID_MASK = 0x7FF
TRANSMIT_EVERY_SYNC = 1  # synchronous, cyclic: sent at every SYNC
PDO_BYTES = 8


@dataclass(frozen=True)
class TpdoSlot:
    """A TPDO the dictionary has: its number (0-based) and how many objects its mapping holds."""

    number: int
    entries: int

    @property
    def communication(self) -> int:
        return TPDO_COMMUNICATION + self.number

    @property
    def mapping(self) -> int:
        return TPDO_MAPPING + self.number


@dataclass(frozen=True)
class TpdoConfig:
    """One TPDO's configuration: the COB-ID (with its flag bits), the transmission type, the mapping objects'
    entries (sub 1 on; a saved configuration has them all, also those beyond the count) and how many are mapped."""

    slot: TpdoSlot
    cob_id: int
    transmission_type: int
    entries: tuple[int, ...]
    count: int

    @property
    def identifier(self) -> int:
        return self.cob_id & COB_ID_MASK


def tpdo_slots(dictionary: ObjectDictionary) -> list[TpdoSlot]:
    """The TPDOs whose communication and mapping objects the dictionary has, with writable mappings and a COB-ID of
    their own: a TPDO whose default COB-ID has no identifier (CiA 301 predefines them for TPDO 1–4 only; the
    encoTRive's TPDO 5 and 6 default to 0x80000000) would transmit on 0x000 — the NMT identifier every node obeys."""
    slots = []
    for number in range(TPDO_LIMIT):
        count = dictionary.get(TPDO_MAPPING + number, 0)
        cob_id = dictionary.get(TPDO_COMMUNICATION + number, 1)
        if count is None or cob_id is None or not count.access.writable or not cob_id.access.writable:
            continue
        if isinstance(cob_id.default, int) and not cob_id.default & COB_ID_MASK:
            continue
        entries = sum(1 for sub in range(1, 65) if dictionary.get(TPDO_MAPPING + number, sub) is not None)
        if entries:
            slots.append(TpdoSlot(number, entries))
    return slots


def mapping_entry(variable: Variable) -> int:
    """A mapping entry: index << 16 | sub << 8 | size in bits."""
    return variable.index << 16 | variable.subindex << 8 | variable.data_type.fixed_size * 8


def read_tpdo(drive: Drive, slot: TpdoSlot) -> TpdoConfig:
    """The TPDO as it is, every mapping entry included (so that writing it back restores the object whole)."""
    reads = [(slot.communication, 1), (slot.communication, 2), (slot.mapping, 0)]
    cob_id, kind, count = (_integer(drive, key) for key in reads)
    subs = drive.submit_read_all([drive.variable((slot.mapping, sub)) for sub in range(1, slot.entries + 1)])
    return TpdoConfig(slot, cob_id, kind, tuple(_raise_or_int(outcome) for outcome in subs.outcomes()), count)


def write_tpdo(drive: Drive, config: TpdoConfig) -> None:
    """Write a TPDO's configuration in CiA 301's order (the first failure raises; later writes are not sent)."""
    slot = config.slot
    writes: list[tuple[tuple[int, int], int]] = [
        ((slot.communication, 1), config.cob_id | COB_ID_INVALID),
        ((slot.mapping, 0), 0),
        *(((slot.mapping, sub), entry) for sub, entry in enumerate(config.entries, 1)),
        ((slot.mapping, 0), config.count),
        ((slot.communication, 2), config.transmission_type),
        ((slot.communication, 1), config.cob_id),
    ]
    batch = drive.submit_write_all([(drive.variable(key), value) for key, value in writes])
    for outcome in batch.outcomes():
        if isinstance(outcome, Exception):
            raise outcome


def synchronous(config: TpdoConfig, variables: list[Variable]) -> TpdoConfig:
    """The TPDO sent at every SYNC with ``variables``, on its own identifier (made valid)."""
    entries = tuple(map(mapping_entry, variables))
    return TpdoConfig(config.slot, config.identifier, TRANSMIT_EVERY_SYNC, entries, len(entries))


def _integer(drive: Drive, key: tuple[int, int]) -> int:
    value = drive.read(key).raw
    assert isinstance(value, int)
    return value


def _raise_or_int(outcome: object) -> int:
    if isinstance(outcome, Exception):
        raise outcome
    value = getattr(outcome, "raw", None)
    assert isinstance(value, int)
    return value
