"""A simulated bus whose drives are locked to the SYNC while SYNCs flow (docs/frequency-response.md §4), for the
frequency-response tests: a Python SYNC thread cannot keep 1 ms on a loaded host (the GIL's 5-ms switch interval,
the simulation's own thread, the OS scheduler), while a drive that synchronises its cycle to the SYNC sees SYNCs one
communication period apart in its own time.  The locked clock is that drive: each SYNC advances the simulated time
by exactly one SYNC period, and the value sent just before it is applied at it; between streams the simulation runs
``speed`` × faster than the wall clock."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager

from servostudio.drive.sync import SYNC_COB_ID
from servostudio.services.bus import ConnectionManager
from servostudio.services.frequency.measure import SYNC_PERIOD_S
from servostudio.sim.network import DeviceBehaviourFactory, SimulatedNetwork

#: the SYNC stream has ended when none came for this long (wall clock): long enough for a SYNC thread held up by a
#: loaded host (an unlock in the middle of a stream would run the drive on without its excitation), short enough for
#: the SDO requests after the stream (0.5 s timeout)
UNLOCK_AFTER_S = 0.25


class SyncLockedClock:
    """Virtual time at ``speed`` × the wall clock, except while SYNCs flow: each then advances it by one period."""

    def __init__(self, network: SimulatedNetwork, speed: float, period_s: float) -> None:
        self.network, self.speed, self.period_s = network, speed, period_s
        self._state = threading.Lock()
        self._last_sync = 0.0
        self._next: float | None = None
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="sync-locked-clock", daemon=True)

    def start(self) -> SyncLockedClock:
        self._thread.start()
        return self

    def stop(self) -> None:
        self._stop.set()
        self._thread.join()

    def on_sync(self) -> None:
        """A SYNC is about to enter the bus: first run the simulation to its slot."""
        with self._state:
            self._last_sync = time.monotonic()
            now = self.network.now
            slot = now if self._next is None else max(self._next, now)
            if slot > now:
                self.network.advance(slot - now)
            self._next = slot + self.period_s

    def _run(self) -> None:
        origin = (time.monotonic(), self.network.now)
        while not self._stop.is_set():
            with self._state:
                if self._next is not None and time.monotonic() - self._last_sync > UNLOCK_AFTER_S:
                    self._next = None  # the stream ended: pace against the wall clock again from here
                    origin = (time.monotonic(), self.network.now)
                if self._next is None:
                    allowed = origin[1] + (time.monotonic() - origin[0]) * self.speed
                    if self.network.now < allowed:
                        self.network.advance(min(0.001, allowed - self.network.now))
                        continue
                else:
                    origin = (time.monotonic(), self.network.now)
            time.sleep(0.0005)


class _Simulation:
    def __init__(self, clock: SyncLockedClock) -> None:
        self.clock = clock

    def stop(self) -> None:
        self.clock.stop()


def locked_bus(network: SimulatedNetwork, clock: SyncLockedClock) -> Callable[[], object]:
    """The in-process bus, its SYNC frames passed through the clock first."""

    def open_bus() -> object:
        bus = network.open_bus()
        send_frame = bus.send_frame

        def send(cob_id: int, data: bytes) -> None:
            if cob_id == SYNC_COB_ID:
                clock.on_sync()
            send_frame(cob_id, data)

        bus.send_frame = send  # type: ignore[method-assign]
        return bus

    return open_bus


def locked_network(
    nodes: str, speed: float, factory: DeviceBehaviourFactory | None = None
) -> tuple[Callable[[], object], _Simulation, SimulatedNetwork]:
    """A network of ``nodes``, its bus opener (SYNCs through the locked clock) and what stops it."""
    network = SimulatedNetwork(nodes, behaviour_factory=factory)
    clock = SyncLockedClock(network, speed, SYNC_PERIOD_S).start()
    return locked_bus(network, clock), _Simulation(clock), network


@contextmanager
def sync_locked_sim(speed: float = 1.0) -> Iterator[None]:
    """Every ``sim`` bus a ConnectionManager opens meanwhile is SYNC-locked (the server's and the CLI's too)."""
    original = ConnectionManager._opener

    def opener(self: ConnectionManager, spec):  # type: ignore[no-untyped-def]
        if spec.kind != "sim":
            return original(self, spec)
        bus, simulation, _ = locked_network(spec.channel or "1,2,3", speed)
        return bus, simulation

    ConnectionManager._opener = opener  # type: ignore[method-assign]
    try:
        yield
    finally:
        ConnectionManager._opener = original  # type: ignore[method-assign]
