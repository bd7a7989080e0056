"""The server's SYNC producer on one bus (CiA 301 SYNC: COB-ID 0x080, no data), for captures through TPDOs.

Each drive samples its synchronous TPDOs when the SYNC frame reaches it, and every drive of the bus receives the
same frame at the same instant: that is what aligns the channels of several axes. The producer runs on a thread
of its own and schedules each frame on a grid from the first one (``start + slot × period``), so a late frame does
not delay the ones after it; every send instant is noted, and `jitter_ns` says how far the frames were from their
slots. A thread held up longer than a period (a loaded host) skips the slots it missed, as a bus master does,
instead of sending them in a burst: two SYNCs are never less than half a period apart, because a burst would give
a free-running drive samples at one instant and a SYNC-locked one a cycle out of step.

With ``answered`` (how many SYNCs the consumers have seen the answers of) the producer stays at most
``MAX_AHEAD`` SYNCs ahead of them: a bus that cannot carry the answers in time (or a simulated bus behind real
time) then gets its SYNCs later — which the jitter states — instead of a backlog that starves every frame of
lower priority (SDO included) for good.
"""

from __future__ import annotations

import logging
import math
import threading
import time
from collections.abc import Callable

from servostudio.drive.access import Drive
from servostudio.drive.link import BusLink, LinkDownError
from servostudio.errors import ServoStudioError

log = logging.getLogger(__name__)

SYNC_COB_ID = 0x080
#: CiA 301 communication cycle period (µs): the SYNC spacing a consumer synchronises its control cycle to
CYCLE_PERIOD = (0x1006, 0)
#: the shortest period offered: a Python thread on a loaded host keeps 1 ms to a fraction of it, not 100 µs
MIN_PERIOD_S = 1e-3
#: SYNCs sent whose answers have not all arrived, at most (the answers of one are on the bus while the next leaves)
MAX_AHEAD = 2
#: how often a producer held back by its consumers looks again
HOLD_SECONDS = 2e-4


class SyncProducer:
    """SYNC frames every ``period_s`` until stopped (or a lost link ends them)."""

    def __init__(
        self,
        link: BusLink,
        period_s: float,
        answered: Callable[[], int] | None = None,
        before: Callable[[int], None] | None = None,
        minimum_s: float = MIN_PERIOD_S,
    ) -> None:
        if period_s < minimum_s:
            raise ValueError(f"SYNC period {period_s * 1e6:.0f} µs below {minimum_s * 1e6:.0f} µs")
        self.link = link
        self.period_s = period_s
        self.sent: list[float] = []  # monotonic send instants
        self.slots: list[int] = []  # each one's slot on the grid (a gap: slots skipped)
        self.error: str | None = None
        self._answered = answered
        #: called with k just before SYNC k is sent (the frequency response's RPDO, applied at that SYNC)
        self._before = before
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name=f"sync {link.name}", daemon=True)

    def start(self) -> SyncProducer:
        self._thread.start()
        return self

    def stop(self) -> None:
        self._stop.set()
        if self._thread.is_alive() and self._thread is not threading.current_thread():
            self._thread.join(5.0)

    @property
    def count(self) -> int:
        return len(self.sent)

    @property
    def skipped(self) -> int:
        """Slots the producer missed (held up beyond a period) and left out."""
        return self.slots[-1] + 1 - len(self.slots) if self.slots else 0

    def jitter_ns(self) -> int:
        """The largest distance of a SYNC from its slot (the first frame's time + slot × period)."""
        if not self.sent:
            return 0
        first = self.sent[0]
        offsets = (abs(t - first - slot * self.period_s) for slot, t in zip(self.slots, self.sent, strict=True))
        return round(max(offsets) * 1e9)

    def _run(self) -> None:
        start = time.monotonic()
        slot = k = 0
        while not self._stop.is_set():
            delay = start + slot * self.period_s - time.monotonic()
            if delay > 0 and self._stop.wait(delay):
                return
            try:
                if not self._wait_for_answers(k):
                    return
                if self._before is not None:
                    self._before(k)
                self.link.send(SYNC_COB_ID, b"")
            except LinkDownError as error:
                self.error = str(error)
                return
            sent = time.monotonic()
            self.sent.append(sent)
            self.slots.append(slot)
            k += 1
            slot = max(slot + 1, math.ceil((sent - start) / self.period_s + 0.5))

    def _wait_for_answers(self, k: int) -> bool:
        """Until fewer than ``MAX_AHEAD`` SYNCs are unanswered; False when stopped meanwhile. A link lost meanwhile
        raises `LinkDownError`: the answers will never come, and no send of this thread would tell of the cut — a
        capture would wait for its timeout instead of failing at once."""
        while self._answered is not None and k - self._answered() >= MAX_AHEAD:
            self.link.check_connected()
            if self._stop.wait(HOLD_SECONDS):
                return False
        return True


def announce_cycle(drive: Drive, period_s: float) -> int | None:
    """Write the SYNC period into the consumer's 0x1006, so that a drive that synchronises its cycle to the SYNC
    (the simulator does: docs/simulator.md) expects this one; the value it had, to put back with `restore_cycle`.
    None when the drive has no 0x1006 or refuses the value (it then runs on its own cycle, as without the write)."""
    if drive.dictionary is None or drive.dictionary.get(*CYCLE_PERIOD) is None:
        return None
    try:
        previous = int(drive.read(CYCLE_PERIOD).raw)
        drive.write(CYCLE_PERIOD, round(period_s * 1e6))
    except ServoStudioError as error:
        log.warning("node %d: communication cycle period not set (%s); its cycle does not follow the SYNC", drive.node,
                    error)  # fmt: skip
        return None
    return previous


def restore_cycle(drive: Drive, previous: int | None) -> None:
    """0x1006 back to what `announce_cycle` found (nothing when it wrote nothing)."""
    if previous is not None:
        drive.write(CYCLE_PERIOD, previous)
