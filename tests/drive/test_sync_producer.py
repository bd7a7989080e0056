"""The SYNC producer held up (a loaded host, a send that blocks): it skips the slots it missed instead of sending
them in a burst, so a free-running drive never gets two samples at one instant."""

from __future__ import annotations

import itertools
import threading
import time

from servostudio.drive.sync import SYNC_COB_ID, SyncProducer

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
