"""A python-can `BusABC` attached to a `SimulatedNetwork`, so python-can and `canopen` clients in the same process
talk to the simulated drives (what `servostudio serve` uses by default).

Frames a client sends enter the virtual bus at the current virtual time; frames on the bus are queued for the
client with their virtual timestamps. A remote frame (`is_remote_frame`) stays a remote frame.

Besides python-can's `recv`/`send`, the bus offers `receive_frames` (every queued data frame at once, as plain
tuples) and `send_frame`, which the communication server's bus link uses on its hot path.
"""

from __future__ import annotations

import queue
from typing import TYPE_CHECKING, Any

import can

from servostudio.sim.frame import Frame

if TYPE_CHECKING:
    from servostudio.sim.network import SimulatedNetwork

RECEIVE_QUEUE_LIMIT = 100_000
"""Frames kept for a client that does not read; beyond it frames are dropped and counted (`overruns`), as a CAN
controller's receive buffer overflows."""


def to_message(frame: Frame, timestamp: float, channel: str | None = None) -> can.Message:
    return can.Message(
        timestamp=timestamp,
        arbitration_id=frame.can_id,
        is_extended_id=frame.extended,
        is_remote_frame=frame.rtr,
        dlc=frame.dlc,
        data=None if frame.rtr else frame.data,
        channel=channel,
        is_rx=True,
    )


def from_message(message: can.Message) -> Frame:
    if message.is_error_frame or message.is_fd:
        raise can.CanOperationError("the simulated bus carries classical CAN data and remote frames only")
    if message.is_remote_frame:
        return Frame(message.arbitration_id, bytes(message.dlc), rtr=True, extended=message.is_extended_id)
    return Frame(message.arbitration_id, bytes(message.data[: message.dlc]), extended=message.is_extended_id)


class SimulatedCanBus(can.BusABC):
    def __init__(self, network: SimulatedNetwork, channel: str = "sim", **kwargs: Any) -> None:
        self._network = network
        self._received: queue.SimpleQueue[can.Message] = queue.SimpleQueue()
        self.overruns = 0
        self.channel_info = f"simulated CAN bus ({len(network.nodes)} drives)"
        super().__init__(channel=channel, **kwargs)
        self.channel = channel
        network.attach(self)

    def receive(self, frame: Frame, timestamp: float) -> None:
        """Station side: called by the virtual bus (under the network lock)."""
        if self._received.qsize() >= RECEIVE_QUEUE_LIMIT:
            self.overruns += 1
            return
        self._received.put(to_message(frame, timestamp, self.channel))

    def _recv_internal(self, timeout: float | None) -> tuple[can.Message | None, bool]:
        try:
            return self._received.get(timeout=timeout), False
        except queue.Empty:
            return None, False

    def receive_frames(self, timeout: float | None) -> list[tuple[int, bytes, float, bool]]:
        """(identifier, data, timestamp, extended) of every data frame queued, waiting up to `timeout` for one."""
        messages = []
        try:
            messages.append(self._received.get(timeout=timeout))
            while True:
                messages.append(self._received.get_nowait())
        except queue.Empty:
            pass
        return [
            (message.arbitration_id, bytes(message.data), message.timestamp, message.is_extended_id)
            for message in messages
            if not message.is_remote_frame
        ]

    def send(self, msg: can.Message, timeout: float | None = None) -> None:
        self._network.inject(from_message(msg), sender=self)

    def send_frame(self, cob_id: int, data: bytes) -> None:
        """A standard data frame, without building a python-can Message."""
        self._network.inject(Frame(cob_id, bytes(data)), sender=self)

    def shutdown(self) -> None:
        self._network.detach(self)
        super().shutdown()
