"""The link of a PROFIBUS-DP bus as the connection and the services see a bus: connected while the DP line is
usable, closed with the bus, and no CAN frames (docs/profibus.md §9).

A `BusConnection` holds a `BusLink`; a PROFIBUS bus's is this subclass, so everything that asks a link whether it
is connected, why not, or to close works unchanged. What only a CAN bus can carry — SDO block transfers, NMT,
SYNC, TPDO/RPDO streams — reaches `send`/`subscribe` and is refused there with `NoCanFrames` (409, exit 3), a
clear answer instead of a frame into nowhere. The DP master itself (a `DpLine` of `transport/profibus/`:
pyprofibus's or the project's own) is reached only through `master`.
"""

from __future__ import annotations

import can

from servostudio.drive.link import BusLink, FrameCallback
from servostudio.errors import Conflict
from servostudio.transport.profibus.interface import DpLine


class NoCanFrames(Conflict):
    """A PROFIBUS-DP bus was asked for something only a CANopen bus does (NMT, SYNC, PDOs, SDO block upload)."""


def refusal(bus: str, what: str) -> NoCanFrames:
    return NoCanFrames(
        f"bus {bus} is a PROFIBUS-DP line: {what} needs a CANopen bus (a TTA-PRO has no NMT, SYNC, TPDO/RPDO "
        "or SDO block transfer; its parameters travel through PKW, its control through PZD)"
    )


_FRAMES = {0x000: "an NMT command", 0x080: "the SYNC"}


def _no_can_bus() -> can.BusABC:
    raise OSError("a PROFIBUS-DP line is not a CAN bus")


class ProfibusLink(BusLink):
    """Connected from `start` until `close`. A station that stops answering, or a line that fails, fails the
    transfers of its drives (each with its reason); the DP master opens a failed line again on its next request."""

    def __init__(self, name: str, master: DpLine) -> None:
        super().__init__(name, _no_can_bus)
        self.master = master

    def start(self, wait: float = 0.0) -> bool:
        """The DP master opened its line when it was built: the link is up (no reader thread: the DP master and
        the cyclic exchanges own the line)."""
        if not self.closed and not self.connected:
            self._connected.set()
            self._first_attempt.set()
            self._notify(True, "connected")
        return self.connected

    def close(self) -> None:
        """Tell the listeners first (the engine stops its cyclic exchanges), then close the line."""
        self._stop.set()
        self._connected.clear()
        self.last_error = "closed"
        self._notify(False, "closed")
        self.master.close()

    def send(self, cob_id: int, data: bytes) -> None:
        raise refusal(self.name, _FRAMES.get(cob_id, f"a CAN frame (COB-ID 0x{cob_id:03X})"))

    def subscribe(self, cob_id: int, callback: FrameCallback) -> None:
        raise refusal(self.name, f"listening to CAN frames (COB-ID 0x{cob_id:03X})")
