"""The SYNC producer held up (a loaded host, a send that blocks): it skips the slots it missed instead of sending
them in a burst, so a free-running drive never gets two samples at one instant; held back by its consumers when the
link is cut, it stops at once with the link's error."""

from __future__ import annotations

import itertools
import re
import threading
import time

from servostudio.drive.link import BusLink
from servostudio.drive.sync import MAX_AHEAD, SYNC_COB_ID, SyncProducer

PERIOD = 0.01
STALL = 0.045  # 4.5 periods


class StallingLink:
    """A link whose third SYNC takes `STALL` to send, as a starved thread would."""

    name = "stalling"

    def __init__(self) -> None:
        self.frames: list[tuple[int, bytes]] = []
        self.enough = threading.Event()

    def send(self, cob_id: int, data: bytes) -> None:
        self.frames.append((cob_id, data))
        if len(self.frames) == 3:
            time.sleep(STALL)
        if len(self.frames) >= 12:
            self.enough.set()


def test_a_held_up_producer_skips_the_slots_it_missed_instead_of_bursting():
    link = StallingLink()
    numbers: list[int] = []
    producer = SyncProducer(link, PERIOD, before=numbers.append).start()  # type: ignore[arg-type]
    assert link.enough.wait(5.0)
    producer.stop()
    spacings = [later - earlier for earlier, later in itertools.pairwise(producer.sent)]
    assert min(spacings) >= PERIOD / 2  # no burst after the stall
    assert producer.skipped >= 3  # the slots the stall covered are left out, not sent late
    assert numbers == list(range(len(numbers))) and len(numbers) >= len(producer.sent)  # SYNC k is the k-th sent
    assert all(frame == (SYNC_COB_ID, b"") for frame in link.frames)


class CuttableBus:
    """A bus that carries the SYNCs until it is cut; nothing ever answers them."""

    def __init__(self) -> None:
        self.sent: list[int] = []
        self.cut = threading.Event()

    def receive_frames(self, timeout: float) -> list:
        if self.cut.wait(timeout):
            raise OSError("connection closed by the server")
        return []

    def send_frame(self, cob_id: int, data: bytes) -> None:
        self.sent.append(cob_id)

    def shutdown(self) -> None:
        pass

    def reopen(self) -> CuttableBus:
        """The opener: once cut, the far end is gone (as a stopped socketcand server)."""
        if self.cut.is_set():
            raise OSError("connection refused")
        return self


def test_a_link_lost_while_the_producer_waits_for_answers_ends_it_at_once():
    """The producer held back by its consumers sends nothing, so no failed send tells it of the cut: it must see the
    link go down itself, or a capture whose answers stopped with the link waits for its timeout."""
    bus = CuttableBus()
    link = BusLink("cuttable", bus.reopen)  # type: ignore[arg-type]
    assert link.start(wait=1.0)
    producer = SyncProducer(link, PERIOD, answered=lambda: 0).start()
    deadline = time.monotonic() + 2.0
    while len(bus.sent) < MAX_AHEAD and time.monotonic() < deadline:
        time.sleep(PERIOD)
    time.sleep(3 * PERIOD)  # held back: MAX_AHEAD SYNCs out, none answered
    assert len(bus.sent) == MAX_AHEAD and producer.error is None
    bus.cut.set()
    deadline = time.monotonic() + 1.0
    while producer.error is None and time.monotonic() < deadline:
        time.sleep(PERIOD)
    producer.stop()
    link.close()
    assert producer.error is not None
    # with the link's reason: recorded before the link reads as down (a later reconnection attempt may have renewed it)
    assert re.search(
        r"bus cuttable is not connected \((connection closed by the server|connection refused)\)", producer.error
    )
