"""The simulated drives' control cycle synchronised to the SYNC, as a real CiA 402 drive synchronises its cycle to its
master's SYNC (docs/simulator.md, "SYNC-locked time").

A master's SYNC thread is late by a fraction of a millisecond on a real bus, and by several milliseconds in bursts on
a loaded host (a Python thread, the GIL's 5-ms switch interval): a drive whose cycle follows the SYNC still sees the
SYNCs one communication cycle period (0x1006) apart in its own time. The simulation does the same while it runs in
real time (`SimulatedNetwork.start`): once ``AGREE`` SYNCs from outside have come about one configured period apart
(the mean wall-clock spacing of each half of them within ``TOLERANCE`` × a period some drive has in 0x1006: a
single probe SYNC followed by a stream at another period does not pass for it), the network is *locked*:

- each SYNC enters the bus at its slot, exactly one period after the previous one (virtual time first runs to it:
  a SYNC early in wall-clock time finds the drives there at once), and a frame sent just before it enters first;
- between two SYNCs virtual time follows the wall clock from the last slot, but stops half a period before the next
  slot: a late SYNC finds the drives waiting for it, and the frames sent just before it (the master's RPDO) still
  have that half period of bus time to be delivered before it — a value is applied at its SYNC whether the SYNC
  thread was early or late (with the ceiling at the slot, a late SYNC came one frame later, sometimes past a control
  period, and the excitation jittered by a control period).

It unlocks, and virtual time paces against the wall clock again, when no SYNC came for ``UNLOCK_AFTER_S`` or no drive
has the period in 0x1006 any more. A single SYNC (a probe), SYNCs at another period than 0x1006 and the drives' own
SYNC (0x1005 bit 30) leave the simulation free-running.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable, Collection
from dataclasses import dataclass

#: SYNCs whose mean spacing must agree with a configured period before the cycle locks (~24 ms at 0.75 ms)
AGREE = 32
#: the mean wall-clock spacing agrees when within a factor of this of the period (a loaded host delivers in bursts;
#: the XtrapulsPac's 10-ms default against a 1-ms scope SYNC is a factor of 10)
TOLERANCE = 1.5
#: wall-clock silence that ends a stream: long enough for a SYNC thread held up by a loaded host (an unlock in the
#: middle of a stream would run the drive on without its excitation), short enough for the SDO requests after it
UNLOCK_AFTER_S = 0.25


@dataclass(frozen=True)
class Window:
    """While locked: the last SYNC's wall-clock instant and slot, and how far virtual time may run before the next."""

    wall: float
    slot: float
    ceiling: float


class SyncLock:
    """Where SYNCs from outside enter the simulation, and how far virtual time may run meanwhile."""

    def __init__(self, periods: Callable[[], Collection[float]]) -> None:
        #: the communication cycle periods (s) the SYNC's consumers have configured (0x1006 > 0)
        self._periods = periods
        self._arrivals: deque[float] = deque(maxlen=AGREE)
        self.period_s = 0.0
        self._window: Window | None = None

    @property
    def locked(self) -> bool:
        return self._window is not None

    def slot(self, now: float, wall: float) -> float:
        """The virtual instant a SYNC arriving at ``wall`` (monotonic) enters: its slot when locked, else ``now``."""
        self._arrivals.append(wall)
        if self._window is None:
            self.period_s = self._agreeing()
            if self.period_s == 0:
                return now
            slot = now
        else:
            slot = max(self._window.slot + self.period_s, now)
        self._window = Window(wall, slot, slot + self.period_s / 2)
        return slot

    def window(self, wall: float) -> Window | None:
        """The lock's window at ``wall``, or None when free-running (after silence or a period changed: unlocked)."""
        window = self._window
        if window is not None and (wall - window.wall > UNLOCK_AFTER_S or self.period_s not in self._periods()):
            self._window = None
            self._arrivals.clear()
        return self._window

    def _agreeing(self) -> float:
        """The configured period both halves of the recent SYNCs came at, or 0."""
        arrivals = list(self._arrivals)
        if len(arrivals) < AGREE:
            return 0.0
        half = AGREE // 2
        means = [(part[-1] - part[0]) / (len(part) - 1) for part in (arrivals[: half + 1], arrivals[half:])]
        agreeing = [period for period in self._periods() if all(_near(mean, period) for mean in means)]
        return min(agreeing, key=lambda period: abs(means[1] - period), default=0.0)


def _near(mean: float, period: float) -> bool:
    return period / TOLERANCE <= mean <= period * TOLERANCE
