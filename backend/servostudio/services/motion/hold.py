"""Hold-to-run: a motion that runs only while its controller's keepalive keeps arriving.

A held motion (``"hold": true``) is registered here with the client that started it; that client sends
``{"type": "keepalive", "bus", "node"}`` on its event socket every ``KEEPALIVE_PERIOD`` (the browser while the
button is held and the tab is visible and focused, the CLI while the command runs).  When none arrived for
``HOLD_TIMEOUT`` the watchdog hands the axis to its ``expired`` callback, which quick-stops it.

The watchdog is a thread of its own, woken at the next deadline: it does not depend on the server's asyncio loop
being idle.  A loop too busy to read the sockets delays the keepalives, never the stop — the axis then stops early,
which is the safe side.  Budget for "stopped within 200 ms of the last keepalive": the timeout (100 ms) + the
watchdog's lateness (a thread wake-up, ~1 ms; ``MIN_WAIT``) + the quick stop's control word (one status read and
one write, a few ms) — about half the budget is left for a loaded machine.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from dataclasses import dataclass

from servostudio.services.motion.control import Axis

#: seconds between two keepalives of the controlling client (browser and CLI)
KEEPALIVE_PERIOD = 0.05
#: seconds without a keepalive after which a held motion is quick-stopped: two periods, so one late keepalive is
#: tolerated and a vanished client is noticed 100 ms after its last one
HOLD_TIMEOUT = 0.1
#: the watchdog's shortest wait (seconds): a deadline due within it is checked again after it, not spun on
MIN_WAIT = 0.001

Expired = Callable[[Axis, str, float], None]  # (axis, client, monotonic time of its last keepalive)


@dataclass
class Hold:
    client: str
    last: float  # time.monotonic() of the last keepalive (or of the start)


class HoldWatch:
    """The held axes and their watchdog thread (started with the first hold, a daemon: it holds nothing at exit;
    ``close`` ends it when its server shuts down, so every app a process builds and closes leaves no thread)."""

    def __init__(self, expired: Expired, timeout: float = HOLD_TIMEOUT) -> None:
        self.expired = expired
        self.timeout = timeout
        self._holds: dict[Axis, Hold] = {}
        self._changed = threading.Condition()
        self._thread: threading.Thread | None = None

    def hold(self, axis: Axis, client: str) -> None:
        """From now on ``client`` must keep the axis alive; the start counts as its first keepalive."""
        with self._changed:
            self._holds[axis] = Hold(client, time.monotonic())
            if self._thread is None:
                self._thread = threading.Thread(target=self._watch, name="motion-hold-watch", daemon=True)
                self._thread.start()
            self._changed.notify()

    def keepalive(self, client: str, axis: Axis) -> float | None:
        """The client's keepalive for the axis; returns its time (monotonic), None when it holds no motion there."""
        now = time.monotonic()
        with self._changed:
            held = self._holds.get(axis)
            if held is None or held.client != client:
                return None
            held.last = now
        return now

    def drop(self, axis: Axis) -> None:
        """The motion ended (done, stopped, failed): no keepalive is needed any more."""
        with self._changed:
            self._holds.pop(axis, None)

    def last(self, axis: Axis) -> float | None:
        with self._changed:
            held = self._holds.get(axis)
            return held.last if held else None

    def close(self, wait: float = 1.0) -> None:
        """End the watchdog thread (waiting up to ``wait`` seconds for it).  Called after the server closed its
        buses, so a hold that expires while they close is still stopped.  A later ``hold`` starts a new one."""
        with self._changed:
            thread, self._thread = self._thread, None
            self._changed.notify_all()
        if thread is not None and thread is not threading.current_thread():
            thread.join(wait)

    def _watch(self) -> None:
        while (due := self._due()) is not None:
            for axis, held in due:
                self.expired(axis, held.client, held.last)

    def _due(self) -> list[tuple[Axis, Hold]] | None:
        """Wait until a hold's deadline passed; return (and forget) every hold that expired, or None once this
        thread is no longer the watchdog (``close``)."""
        with self._changed:
            while self._thread is threading.current_thread():
                now = time.monotonic()
                due = [(axis, held) for axis, held in self._holds.items() if now - held.last >= self.timeout]
                if due:
                    for axis, _ in due:
                        del self._holds[axis]
                    return due
                deadlines = [held.last + self.timeout for held in self._holds.values()]
                self._changed.wait(max(min(deadlines) - now, MIN_WAIT) if deadlines else None)
            return None
