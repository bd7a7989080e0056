"""In-process virtual CAN bus with an optional bit-rate timing model.

A transmitter hands a frame to `VirtualBus.transmit`; the bus holds it in the pending set. When the bus is idle, an
arbitration round picks the pending frame with the lowest identifier (a data frame wins over a remote frame with the
same identifier, as the RTR bit is recessive), keeps it on the wire for its exact bit time (`timing.frame_bits`) and
then delivers it to every attached station except its sender. Frames that lose arbitration wait for the next round,
which starts as soon as the wire is free. With `bitrate=None` frames still go through arbitration rounds but take
no time. A station's own frames leave in the order it queued them (a CAN controller's transmit FIFO, as SocketCAN
and USB adapters keep it): only its oldest pending frame takes part in a round, so a client's RPDO sent just before
its SYNC is not overtaken by it. Frames queued without a sender are each a transmitter of their own.

The bus is driven by the `VirtualClock` and is not thread-safe by itself: `SimulatedNetwork` serialises every access
with its lock.
"""

from __future__ import annotations

from typing import Protocol

from servostudio.sim.clock import VirtualClock
from servostudio.sim.frame import Frame
from servostudio.sim.timing import frame_duration

DEFAULT_BITRATE = 1_000_000


class Station(Protocol):
    """Anything attached to the bus: a simulated node, an adapter towards a client, the serial gateway."""

    def receive(self, frame: Frame, timestamp: float) -> None: ...


class VirtualBus:
    def __init__(self, clock: VirtualClock, bitrate: int | None = DEFAULT_BITRATE) -> None:
        if bitrate is not None and bitrate <= 0:
            raise ValueError(f"bit rate must be positive, got {bitrate}")
        self.clock = clock
        self.bitrate = bitrate
        self.frames_delivered = 0
        self._stations: list[Station] = []
        self._pending: list[tuple[int, int, Frame, Station | None]] = []
        self._order = 0
        self._busy = False

    def attach(self, station: Station) -> None:
        self._stations.append(station)

    def detach(self, station: Station) -> None:
        if station in self._stations:
            self._stations.remove(station)

    def transmit(self, frame: Frame, sender: Station | None = None) -> None:
        """Queue `frame` for arbitration; `sender` does not receive its own frame."""
        self._order += 1
        self._pending.append((_priority(frame), self._order, frame, sender))
        if not self._busy:
            self._busy = True
            # Arbitrate in a separate event, so that every frame queued at this same instant takes part.
            self.clock.call_at(self.clock.now, self._arbitrate)

    def _arbitrate(self) -> None:
        if not self._pending:
            self._busy = False
            return
        winner = min(_heads(self._pending))
        self._pending.remove(winner)
        frame, sender = winner[2], winner[3]
        self.clock.call_later(frame_duration(frame, self.bitrate), lambda: self._complete(frame, sender))

    def _complete(self, frame: Frame, sender: Station | None) -> None:
        self.frames_delivered += 1
        now = self.clock.now
        for station in list(self._stations):
            if station is not sender:
                station.receive(frame, now)
        self._arbitrate()


def _heads(pending: list[tuple[int, int, Frame, Station | None]]) -> list[tuple[int, int, Frame, Station | None]]:
    """The frames that take part in a round: each sender's oldest (the list is in queueing order)."""
    seen: set[int] = set()
    heads = []
    for entry in pending:
        sender = entry[3]
        if sender is None or id(sender) not in seen:
            heads.append(entry)
            if sender is not None:
                seen.add(id(sender))
    return heads


def _priority(frame: Frame) -> int:
    """Arbitration key, lower wins: the identifier bits as sent, then the RTR bit (recessive = 1)."""
    if frame.extended:
        # Base identifier first; SRR and IDE are recessive: a standard frame beats an extended one of the same base.
        return (frame.can_id >> 18) << 21 | 0b11 << 19 | (frame.can_id & 0x3FFFF) << 1 | frame.rtr
    return frame.can_id << 21 | frame.rtr << 20
