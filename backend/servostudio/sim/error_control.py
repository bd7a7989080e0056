"""NMT error control of one node: heartbeat producer (0x1017), node guarding (0x100C/0x100D) and heartbeat
consumer (0x1016).

Life guarding starts with the first guarding request; a missing request within guard time × life time factor, or
a monitored heartbeat missing for its consumer time, reports a failure to the node (which applies 0x205E).
"""

from __future__ import annotations

from collections.abc import Callable

from servostudio.sim.clock import Timer, VirtualClock
from servostudio.sim.frame import Frame
from servostudio.sim.nmt import HEARTBEAT_BASE, NmtState
from servostudio.sim.objects import ObjectStore

GUARD_TIME = 0x100C
LIFE_TIME_FACTOR = 0x100D
CONSUMER_HEARTBEAT_TIME = 0x1016
PRODUCER_HEARTBEAT_TIME = 0x1017


class ErrorControl:
    def __init__(
        self,
        store: ObjectStore,
        clock: VirtualClock,
        transmit: Callable[[Frame], None],
        state: Callable[[], NmtState],
        on_failure: Callable[[str], None],
    ) -> None:
        self.store = store
        self.clock = clock
        self._transmit = transmit
        self._state = state
        self._on_failure = on_failure
        self._heartbeat: Timer | None = None
        self._life_guard: Timer | None = None
        self._consumers: dict[int, Timer] = {}
        self._toggle = 0
        self.heartbeats_sent = 0
        if (PRODUCER_HEARTBEAT_TIME, 0) in store:
            store.on_write(PRODUCER_HEARTBEAT_TIME, 0, lambda index, sub, value: self._schedule_heartbeat(int(value)))

    @property
    def cob_id(self) -> int:
        return HEARTBEAT_BASE + self.store.node_id

    def start(self) -> None:
        """(Re)start after boot-up: heartbeat from 0x1017, guarding and consumers idle until their first frame."""
        self.stop()
        self._toggle = 0
        self._schedule_heartbeat(self._value(PRODUCER_HEARTBEAT_TIME, 0))

    def stop(self) -> None:
        for timer in [self._heartbeat, self._life_guard, *self._consumers.values()]:
            if timer is not None:
                timer.cancel()
        self._heartbeat = self._life_guard = None
        self._consumers.clear()

    def _value(self, index: int, sub: int) -> int:
        return int(self.store.get(index, sub)) if (index, sub) in self.store else 0

    # -- heartbeat producer ---------------------------------------------------------------------------------------

    def _schedule_heartbeat(self, period_ms: int) -> None:
        if self._heartbeat is not None:
            self._heartbeat.cancel()
            self._heartbeat = None
        if period_ms > 0:
            self._heartbeat = self.clock.call_later(period_ms * 1e-3, lambda: self._beat(period_ms))

    def _beat(self, period_ms: int) -> None:
        self._transmit(Frame(self.cob_id, bytes((self._state().heartbeat_code,))))
        self.heartbeats_sent += 1
        self._heartbeat = self.clock.call_later(period_ms * 1e-3, lambda: self._beat(period_ms))

    # -- node guarding --------------------------------------------------------------------------------------------

    def guard_request(self) -> None:
        """Answer a remote frame on 0x700+n with the toggle bit and the state; restart life guarding."""
        self._transmit(Frame(self.cob_id, bytes((self._toggle | self._state().heartbeat_code,))))
        self._toggle ^= 0x80
        life_time = self._value(GUARD_TIME, 0) * self._value(LIFE_TIME_FACTOR, 0) * 1e-3
        if self._life_guard is not None:
            self._life_guard.cancel()
            self._life_guard = None
        if life_time > 0:
            self._life_guard = self.clock.call_later(life_time, lambda: self._on_failure("node guarding"))

    # -- heartbeat consumer ---------------------------------------------------------------------------------------

    def heartbeat_received(self, producer: int) -> None:
        if CONSUMER_HEARTBEAT_TIME not in self.store.od:
            return
        for sub in self.store.od.object(CONSUMER_HEARTBEAT_TIME).subs:
            if sub == 0:
                continue
            entry = int(self.store.get(CONSUMER_HEARTBEAT_TIME, sub))
            time_ms = entry & 0xFFFF
            if (entry >> 16) & 0x7F == producer and time_ms:
                previous = self._consumers.pop(producer, None)
                if previous is not None:
                    previous.cancel()
                self._consumers[producer] = self.clock.call_later(
                    time_ms * 1e-3, lambda: self._on_failure(f"heartbeat of node {producer}")
                )
