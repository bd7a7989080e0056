"""Deterministic virtual time for the simulator.

Everything that happens in the simulation (frame on the wire, SDO response, heartbeat, control period of a drive)
is an event on one `VirtualClock`. Events run in time order, and events due at the same instant run in the order
they were scheduled, so a run is reproducible: tests step the clock with `run_until`, the server mode paces it
against the wall clock (see `servostudio.sim.network`).

A *lazy* event (the drives' control periods) runs in the same order as any other, but the real-time loop does not
wake up for it: `next_event_time` names only the others. Lazy events due meanwhile run when the loop wakes for
something else, or at its idle wake-up.
"""

from __future__ import annotations

import heapq
import itertools
from collections.abc import Callable

CONTROL_PERIOD = 250e-6
"""Drive control period in seconds (the XtrapulsPac current/speed loop period)."""


class Timer:
    """Handle of a scheduled event; `cancel()` makes it a no-op."""

    __slots__ = ("callback", "cancelled", "when")

    def __init__(self, when: float, callback: Callable[[], None]) -> None:
        self.when = when
        self.callback = callback
        self.cancelled = False

    def cancel(self) -> None:
        self.cancelled = True


class VirtualClock:
    """Virtual time in seconds plus the queue of events waiting for it."""

    def __init__(self, start: float = 0.0) -> None:
        self.now = start
        self._queue: list[tuple[float, int, Timer]] = []
        self._lazy: list[tuple[float, int, Timer]] = []
        self._sequence = itertools.count()

    def call_at(self, when: float, callback: Callable[[], None], lazy: bool = False) -> Timer:
        """Run `callback` at virtual time `when` (never in the past: late events run now)."""
        timer = Timer(max(when, self.now), callback)
        heapq.heappush(self._lazy if lazy else self._queue, (timer.when, next(self._sequence), timer))
        return timer

    def call_later(self, delay: float, callback: Callable[[], None]) -> Timer:
        return self.call_at(self.now + delay, callback)

    def next_event_time(self) -> float | None:
        """When the next event that is not lazy is due (None: none is scheduled)."""
        while self._queue and self._queue[0][2].cancelled:
            heapq.heappop(self._queue)
        return self._queue[0][0] if self._queue else None

    def run_until(self, when: float) -> None:
        """Run every event due up to `when` (inclusive) in order, then set `now` to `when`."""
        queue, lazy = self._queue, self._lazy
        while True:
            if queue and queue[0][0] <= when and (not lazy or queue[0] < lazy[0]):  # (time, sequence) order
                event_time, _, timer = heapq.heappop(queue)
            elif lazy and lazy[0][0] <= when:
                event_time, _, timer = heapq.heappop(lazy)
            else:
                break
            if timer.cancelled:
                continue
            self.now = event_time
            timer.callback()
        self.now = max(self.now, when)
