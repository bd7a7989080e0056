"""BusLink: frames that arrive together are dispatched as one batch; what the callbacks send leaves in one write."""

from __future__ import annotations

import threading
import time

import can

from servostudio.drive.link import BusLink


class BatchBus(can.BusABC):
    """A bus that delivers prepared batches through ``receive_frames`` and records every write."""

    def __init__(self, batches: list[list[tuple[int, bytes]]]) -> None:
        self.batches = list(batches)
        self.writes: list[list[tuple[int, bytes]]] = []
        self.channel_info = "batch test bus"
        super().__init__(channel="batch")

    def receive_frames(self, timeout):
        if not self.batches:
            time.sleep(timeout)
            return []
        return [(cob_id, data, 1.0, False) for cob_id, data in self.batches.pop(0)]

    def send_frame(self, cob_id: int, data: bytes) -> None:
        self.writes.append([(cob_id, data)])

    def send_frames(self, frames: list[tuple[int, bytes]]) -> None:
        self.writes.append(list(frames))

    def send(self, msg, timeout=None) -> None:
        self.send_frame(msg.arbitration_id, bytes(msg.data))

    def _recv_internal(self, timeout):
        return None, False


def test_answers_to_a_batch_leave_in_one_write_before_the_after_dispatch_callbacks():
    bus = BatchBus([[(0x581, b"\x01"), (0x582, b"\x02"), (0x583, b"\x03")]])
    link = BusLink("batch", lambda: bus)
    order: list[str] = []
    done = threading.Event()

    def answer(cob_id: int, data: bytes, timestamp: float) -> None:
        link.send(cob_id + 0x80, data)
        order.append(f"frame {cob_id:X}")

    def after() -> None:
        order.append(f"after, {len(bus.writes)} write(s)")
        done.set()

    for cob_id in (0x581, 0x582, 0x583):
        link.subscribe(cob_id, answer)
    link.after_dispatch(after)
    assert link.start(wait=2.0)
    try:
        assert done.wait(2.0)
        assert bus.writes == [[(0x601, b"\x01"), (0x602, b"\x02"), (0x603, b"\x03")]]
        assert order == ["frame 581", "frame 582", "frame 583", "after, 1 write(s)"]
        link.send(0x604, b"\x04")  # another thread's send is not held back
        assert bus.writes[-1] == [(0x604, b"\x04")]
    finally:
        link.close()
