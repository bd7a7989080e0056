"""The excitation sent to the drive: one receive PDO, applied at every SYNC, sent by the server's SYNC producer.

The RPDO the measurement borrows (the highest-numbered one the dictionary has) is read whole first and written back
at the end, whatever happens; it is mapped with the one excited object (the torque offset or the target velocity)
and made synchronous (transmission type 1: the drive applies the value at the next SYNC, so every value takes effect
at a SYNC instant).  The node is started (NMT, RPDOs act only in OPERATIONAL) and put back to PRE-OPERATIONAL
afterwards when it was not operational before.  Just before SYNC k the producer's hook sends value k
(``value_of(k)``): value and SYNC leave back to back from one thread, in that order.
"""

from __future__ import annotations

import struct
from collections.abc import Callable
from dataclasses import dataclass

from servostudio.drive.access import Drive
from servostudio.drive.link import BusLink
from servostudio.drive.nmt import NmtCommand, send_nmt
from servostudio.drive.sync import SyncProducer
from servostudio.drive.tpdo import COB_ID_INVALID, COB_ID_MASK, mapping_entry
from servostudio.errors import CommunicationError, ServoStudioError
from servostudio.od.datatypes import DataType
from servostudio.od.model import Variable

RPDO_COMMUNICATION, RPDO_MAPPING = 0x1400, 0x1600
RPDO_LIMIT = 512
APPLY_AT_EVERY_SYNC = 1
FORMATS = {DataType.INTEGER16: "<h", DataType.INTEGER32: "<i", DataType.UNSIGNED16: "<H", DataType.UNSIGNED32: "<I"}


class NoRpdo(CommunicationError):
    """The drive offers no receive PDO the measurement can map its excitation into."""


@dataclass(frozen=True)
class RpdoConfig:
    number: int  # 0-based
    cob_id: int
    transmission_type: int
    entries: tuple[int, ...]
    count: int

    @property
    def identifier(self) -> int:
        return self.cob_id & COB_ID_MASK


class ExcitationStream:
    """The borrowed RPDO, the SYNC producer that carries the excitation, and putting both back."""

    def __init__(self, drive: Drive, link: BusLink, variable: Variable, period_s: float) -> None:
        self.drive, self.link, self.variable, self.period_s = drive, link, variable, period_s
        self.layout = struct.Struct(FORMATS[DataType(variable.data_type)])
        self.saved: RpdoConfig | None = None
        self.producer: SyncProducer | None = None
        self.started_node = False

    def open(self, operational: bool) -> None:
        """Borrow and map the RPDO; start the node unless it is OPERATIONAL already (``operational``)."""
        number = _last_rpdo(self.drive)
        self.saved = _read(self.drive, number)
        entry = mapping_entry(self.variable)
        _write(self.drive, RpdoConfig(number, self.saved.identifier, APPLY_AT_EVERY_SYNC, (entry,), 1))
        if not operational:
            send_nmt(self.link, NmtCommand.START, self.drive.node)
            self.started_node = True

    def start(self, value_of: Callable[[int], int]) -> None:
        """SYNC every period from now on, value k sent just before SYNC k."""
        assert self.saved is not None
        identifier, pack = self.saved.identifier, self.layout.pack
        self.producer = SyncProducer(
            self.link,
            self.period_s,
            before=lambda k: self.link.send(identifier, pack(value_of(k))),
            minimum_s=self.period_s,
        )
        self.producer.start()

    @property
    def error(self) -> str | None:
        return self.producer.error if self.producer is not None else None

    def stop(self) -> None:
        if self.producer is not None:
            self.producer.stop()

    def close(self) -> str | None:
        """SYNC stopped, the RPDO written back, the node back to PRE-OPERATIONAL if started; what failed, or None."""
        self.stop()
        failures = []
        if self.saved is not None:
            try:
                _write(self.drive, self.saved)
            except ServoStudioError as error:
                failures.append(f"RPDO {self.saved.number + 1} not written back: {error}")
        if self.started_node:
            try:
                send_nmt(self.link, NmtCommand.PRE_OPERATIONAL, self.drive.node)
            except ServoStudioError as error:
                failures.append(f"node left OPERATIONAL: {error}")
        return "; ".join(failures) or None


def _last_rpdo(drive: Drive) -> int:
    dictionary = drive.dictionary
    for number in reversed(range(RPDO_LIMIT)):
        if (
            dictionary is not None
            and dictionary.get(RPDO_MAPPING + number, 1) is not None
            and (dictionary.get(RPDO_COMMUNICATION + number, 1) is not None)
        ):
            return number
    raise NoRpdo(f"node {drive.node}: the {drive.profile.device} has no receive PDO to carry the excitation")


def _read(drive: Drive, number: int) -> RpdoConfig:
    communication, mapping = RPDO_COMMUNICATION + number, RPDO_MAPPING + number
    keys = [(communication, 1), (communication, 2), (mapping, 0)]
    count_entries = sum(1 for sub in range(1, 65) if drive.dictionary and drive.dictionary.get(mapping, sub))
    keys += [(mapping, sub) for sub in range(1, count_entries + 1)]
    values = [_raw(outcome) for outcome in drive.submit_read_all([drive.variable(key) for key in keys]).outcomes()]
    return RpdoConfig(number, values[0], values[1], tuple(values[3:]), values[2])


def _write(drive: Drive, config: RpdoConfig) -> None:
    """CiA 301's order: COB-ID invalid, count 0, the entries, the count, the transmission type, COB-ID as given."""
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


def _raw(outcome: object) -> int:
    if isinstance(outcome, Exception):
        raise outcome
    value = getattr(outcome, "raw", None)
    assert isinstance(value, int)
    return value
