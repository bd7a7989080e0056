"""Status word watch: the CiA 402 state of every known drive of a bus, polled slowly while a client listens.

The bus monitor reports a state that arrives in a TPDO or that state control read, but a drive in PRE-OPERATIONAL
sends no PDO and a drive also changes state by itself (a fault, a local enable).  So while at least one event
client wants ``drive_state`` events, every known node's status word is read every ``POLL_PERIOD`` and the monitor
reports a change of state.  At most one request per node is in flight; a node that does not answer is asked again
next period.  The watch runs in the bus reader thread's ticker and never waits: no thread of its own, and with
no listener it sends nothing.
"""

from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import CancelledError, Future
from functools import partial
from typing import TYPE_CHECKING

from servostudio.drive.profiles import profile_for
from servostudio.drive.sdo import SdoError

if TYPE_CHECKING:
    from servostudio.services.bus.connections import BusConnection

POLL_PERIOD = 0.5
POLL_TIMEOUT = 0.4


class StatuswordWatch:
    """Polls the status word of a connection's known nodes while ``wanted()`` says a client listens."""

    def __init__(self, connection: BusConnection, wanted: Callable[[], bool]) -> None:
        self.connection = connection
        self._wanted = wanted
        self._next = 0.0
        self._pending: set[int] = set()
        connection.link.add_ticker(self._tick)

    def _tick(self, now: float) -> None:
        connection = self.connection
        if now < self._next or connection.monitor is None or not connection.link.connected or not self._wanted():
            return
        self._next = now + POLL_PERIOD
        for node, info in list(connection.nodes.items()):
            profile = profile_for(info.device) if info.device else None
            if profile is None or not profile.has("statusword") or node in self._pending:
                continue
            index, sub = profile.address("statusword")
            self._pending.add(node)
            future = connection.engine.upload(node, index, sub, timeout=POLL_TIMEOUT)
            future.add_done_callback(partial(self._answered, node))

    def _answered(self, node: int, future: Future) -> None:
        self._pending.discard(node)
        try:
            raw = future.result()
        except (SdoError, CancelledError):
            return
        if len(raw) >= 2 and self.connection.monitor is not None:
            self.connection.monitor.report_statusword(node, int.from_bytes(raw[:2], "little"))
