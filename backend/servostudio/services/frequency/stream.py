"""The excitation sent to the drive: one receive PDO, applied at every SYNC, sent by the server's SYNC producer.

The RPDO the measurement borrows (the highest-numbered one the dictionary has) is read whole first and written back
at the end, whatever happens; it is mapped with the one excited object (the torque offset or the target velocity)
and made synchronous (transmission type 1: the drive applies the value at the next SYNC, so every value takes effect
at a SYNC instant).  The drive's communication cycle period 0x1006 is set to the SYNC period and put back after:
a drive that synchronises its cycle to the SYNC (the simulator does) then takes the values one period apart however
late the SYNC thread is.  The node is started (NMT, RPDOs act only in OPERATIONAL) and put back to PRE-OPERATIONAL
afterwards when it was not operational before.  Just before SYNC k the producer's hook sends value k
(``value_of(k)``): value and SYNC leave back to back from one thread, in that order.
"""

from __future__ import annotations

import itertools
import struct
from collections.abc import Callable

from servostudio.drive.access import Drive
from servostudio.drive.link import BusLink
from servostudio.drive.nmt import NmtCommand, send_nmt
from servostudio.drive.rpdo import APPLY_AT_SYNC, RpdoConfig, last_rpdo, mapped, read_rpdo, write_rpdo
from servostudio.drive.sync import SyncProducer, announce_cycle, restore_cycle
from servostudio.errors import ServoStudioError
from servostudio.od.datatypes import DataType
from servostudio.od.model import Variable

FORMATS = {DataType.INTEGER16: "<h", DataType.INTEGER32: "<i", DataType.UNSIGNED16: "<H", DataType.UNSIGNED32: "<I"}


class ExcitationStream:
    """The borrowed RPDO, the SYNC producer that carries the excitation, and putting both back."""

    def __init__(self, drive: Drive, link: BusLink, variable: Variable, period_s: float) -> None:
        self.drive, self.link, self.variable, self.period_s = drive, link, variable, period_s
        self.layout = struct.Struct(FORMATS[DataType(variable.data_type)])
        self.saved: RpdoConfig | None = None
        self.producer: SyncProducer | None = None
        self.started_node = False
        self.cycle: int | None = None  # the drive's communication cycle period before (None: not written)

    def open(self, operational: bool) -> None:
        """Borrow and map the RPDO, announce the SYNC period (0x1006: a drive locked to the SYNC applies the values
        one period apart however late the SYNC thread is); start the node unless OPERATIONAL (``operational``)."""
        number = last_rpdo(self.drive)
        self.saved = read_rpdo(self.drive, number)
        self.cycle = announce_cycle(self.drive, self.period_s)
        write_rpdo(self.drive, mapped(number, self.saved.identifier, [self.variable], APPLY_AT_SYNC))
        if not operational:
            send_nmt(self.link, NmtCommand.START, self.drive.node)
            self.started_node = True

    def start(self, value_of: Callable[[int], int], answered: Callable[[], int] | None = None) -> None:
        """SYNC every period from now on, value k sent just before SYNC k; with ``answered`` (the SYNCs the response's
        TPDOs have answered) the same producer paces itself by the answers, as a TPDO capture's does."""
        assert self.saved is not None
        identifier, pack = self.saved.identifier, self.layout.pack
        self.producer = SyncProducer(
            self.link,
            self.period_s,
            answered,
            before=lambda k: self.link.send(identifier, pack(value_of(k))),
            minimum_s=self.period_s,
        )
        self.producer.start()

    @property
    def error(self) -> str | None:
        return self.producer.error if self.producer is not None else None

    @property
    def sent(self) -> int:
        """SYNCs sent so far."""
        return self.producer.count if self.producer is not None else 0

    def stalled(self, first: int, last: int, longest_s: float) -> bool:
        """Did any two of SYNCs ``first`` … ``last`` leave more than ``longest_s`` apart (a drive locked to the SYNC
        loses it; the simulator runs free again)?"""
        sent = self.producer.sent[max(first, 0) : last + 1] if self.producer is not None else []
        return any(later - earlier > longest_s for earlier, later in itertools.pairwise(sent))

    def stop(self) -> None:
        if self.producer is not None:
            self.producer.stop()

    def close(self) -> str | None:
        """SYNC stopped, the RPDO and 0x1006 written back, the node back to PRE-OPERATIONAL if started; what failed,
        or None."""
        self.stop()
        failures = []
        try:
            restore_cycle(self.drive, self.cycle)
        except ServoStudioError as error:
            failures.append(f"communication cycle period not written back: {error}")
        if self.saved is not None:
            try:
                write_rpdo(self.drive, self.saved)
            except ServoStudioError as error:
                failures.append(f"RPDO {self.saved.number + 1} not written back: {error}")
        if self.started_node:
            try:
                send_nmt(self.link, NmtCommand.PRE_OPERATIONAL, self.drive.node)
            except ServoStudioError as error:
                failures.append(f"node left OPERATIONAL: {error}")
        return "; ".join(failures) or None
