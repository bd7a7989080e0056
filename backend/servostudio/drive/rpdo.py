"""A node's receive PDOs as a capture borrows them (CiA 301: communication 0x1400+n, mapping 0x1600+n), the
counterpart of ``drive/tpdo.py``.

Which RPDO a service may borrow (`last_rpdo`: the highest-numbered one the dictionary has), its present configuration
read whole (`read_rpdo`, so that writing it back restores every entry), a mapping written in the order CiA 301 asks
of a master — COB-ID invalid, mapping count 0, the entries, the count, the transmission type, the COB-ID as given —
(`write_rpdo`), and the configuration that maps objects on a given identifier (`mapped`).
"""

from __future__ import annotations

from dataclasses import dataclass

from servostudio.drive.access import Drive
from servostudio.drive.tpdo import COB_ID_INVALID, COB_ID_MASK, mapping_entry
from servostudio.errors import CommunicationError
from servostudio.od.model import Variable

RPDO_COMMUNICATION, RPDO_MAPPING = 0x1400, 0x1600
RPDO_LIMIT = 512
APPLY_AT_SYNC = 1  # synchronous: the data takes effect at the next SYNC
APPLY_ON_RECEPTION = 255  # event-driven: the data takes effect when the frame arrives


class NoRpdo(CommunicationError):
    """The drive offers no receive PDO to borrow."""


@dataclass(frozen=True)
class RpdoConfig:
    """One RPDO's configuration: number (0-based), COB-ID with its flag bits, transmission type, the mapping's
    entries (all of them for a saved configuration, also those beyond the count) and how many are mapped."""

    number: int
    cob_id: int
    transmission_type: int
    entries: tuple[int, ...]
    count: int

    @property
    def identifier(self) -> int:
        return self.cob_id & COB_ID_MASK


def last_rpdo(drive: Drive) -> int:
    """The highest-numbered RPDO whose communication and mapping objects the dictionary has, with a COB-ID of its
    own: one whose default COB-ID has no identifier (CiA 301 predefines them for RPDO 1–4 only; the encoTRive's
    RPDO 5 and 6 default to 0x80000000) would be sent on 0x000 — as NMT commands every node obeys."""
    dictionary = drive.dictionary
    for number in reversed(range(RPDO_LIMIT)):
        cob_id = dictionary.get(RPDO_COMMUNICATION + number, 1) if dictionary is not None else None
        if (
            dictionary is not None
            and dictionary.get(RPDO_MAPPING + number, 1) is not None
            and cob_id is not None
            and not (isinstance(cob_id.default, int) and not cob_id.default & COB_ID_MASK)
        ):
            return number
    raise NoRpdo(f"node {drive.node}: the {drive.profile.device} has no receive PDO")


def read_rpdo(drive: Drive, number: int) -> RpdoConfig:
    """The RPDO as it is, every mapping entry included."""
    communication, mapping = RPDO_COMMUNICATION + number, RPDO_MAPPING + number
    keys = [(communication, 1), (communication, 2), (mapping, 0)]
    dictionary = drive.dictionary
    entries = sum(1 for sub in range(1, 65) if dictionary is not None and dictionary.get(mapping, sub) is not None)
    keys += [(mapping, sub) for sub in range(1, entries + 1)]
    values = [_raw(outcome) for outcome in drive.submit_read_all([drive.variable(key) for key in keys]).outcomes()]
    return RpdoConfig(number, values[0], values[1], tuple(values[3:]), values[2])


def write_rpdo(drive: Drive, config: RpdoConfig) -> None:
    """Write an RPDO's configuration in CiA 301's order (the first failure raises)."""
    communication, mapping = RPDO_COMMUNICATION + config.number, RPDO_MAPPING + config.number
    writes: list[tuple[tuple[int, int], int]] = [
        ((communication, 1), config.cob_id | COB_ID_INVALID),
        ((mapping, 0), 0),
        *(((mapping, sub), entry) for sub, entry in enumerate(config.entries, 1)),
        ((mapping, 0), config.count),
        ((communication, 2), config.transmission_type),
        ((communication, 1), config.cob_id),
    ]
    batch = drive.submit_write_all([(drive.variable(key), value) for key, value in writes])
    for outcome in batch.outcomes():
        if isinstance(outcome, Exception):
            raise outcome


def mapped(number: int, identifier: int, variables: list[Variable], transmission_type: int) -> RpdoConfig:
    """RPDO ``number`` carrying ``variables`` on ``identifier`` (valid)."""
    entries = tuple(map(mapping_entry, variables))
    return RpdoConfig(number, identifier & COB_ID_MASK, transmission_type, entries, len(entries))


def _raw(outcome: object) -> int:
    if isinstance(outcome, Exception):
        raise outcome
    value = getattr(outcome, "raw", None)
    assert isinstance(value, int)
    return value
