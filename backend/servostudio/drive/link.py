"""One CAN bus as the drive layer sees it: a reader thread, frame dispatch by COB-ID, sends, reconnection.

python-can's Notifier stops for good on the first receive error; a communication server must instead report
the loss, keep serving other buses, and reopen the interface when it comes back.  ``BusLink`` owns the bus
object: while the link is up a single reader thread receives frames and hands them to the subscribers of their
COB-ID; when a receive or send fails the link goes down (listeners are told why), the bus is closed, and the
thread tries to reopen it every ``reconnect_interval`` seconds.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable

import can

log = logging.getLogger(__name__)

FrameCallback = Callable[[int, bytes, float], None]
StateCallback = Callable[[bool, str], None]
TickCallback = Callable[[float], None]
TICK_INTERVAL = 0.01
POLL_INTERVAL = 0.02


class LinkDownError(ConnectionError):
    """The bus is not connected (never opened, lost, or closed)."""


class BusLink:
    """Frames in and out of one bus, with automatic reconnection."""

    def __init__(self, name: str, opener: Callable[[], can.BusABC], reconnect_interval: float = 1.0) -> None:
        self.name = name
        self.reconnect_interval = reconnect_interval
        self.last_error = ""
        self._opener = opener
        self._bus: can.BusABC | None = None
        self._send_lock = threading.Lock()
        self._subscribers: dict[int, list[FrameCallback]] = {}
        self._state_listeners: list[StateCallback] = []
        self._tickers: list[TickCallback] = []
        self._stop = threading.Event()
        self._connected = threading.Event()
        self._first_attempt = threading.Event()
        self._thread: threading.Thread | None = None
        self._next_tick = 0.0

    # -- lifecycle ---------------------------------------------------------------------------------------------
    def start(self, wait: float = 0.0) -> bool:
        """Start the reader thread; with ``wait`` > 0 block until the first attempt to open the interface
        succeeded or failed (at most that many seconds).  Returns whether the bus is connected."""
        if self._thread is None:
            self._thread = threading.Thread(target=self._run, name=f"bus {self.name}", daemon=True)
            self._thread.start()
        if wait > 0:
            self._first_attempt.wait(wait)
        return self.connected

    def close(self) -> None:
        self._stop.set()
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join(timeout=2.0)
        self._drop_bus()

    @property
    def connected(self) -> bool:
        return self._connected.is_set()

    def wait_connected(self, timeout: float) -> bool:
        return self._connected.wait(timeout)

    # -- frames ------------------------------------------------------------------------------------------------
    def send(self, cob_id: int, data: bytes) -> None:
        bus = self._bus
        if bus is None or not self.connected:
            detail = f" ({self.last_error})" if self.last_error else ""
            raise LinkDownError(f"bus {self.name} is not connected{detail}")
        fast_send = getattr(bus, "send_frame", None)  # our own buses skip building a python-can Message
        try:
            with self._send_lock:
                if fast_send is not None:
                    fast_send(cob_id, data)
                else:
                    bus.send(can.Message(arbitration_id=cob_id, data=data, is_extended_id=False))
        except (can.CanError, OSError) as error:
            self._link_lost(str(error))
            raise LinkDownError(f"bus {self.name}: {error}") from error

    def subscribe(self, cob_id: int, callback: FrameCallback) -> None:
        self._subscribers.setdefault(cob_id, []).append(callback)

    def unsubscribe(self, cob_id: int, callback: FrameCallback) -> None:
        callbacks = self._subscribers.get(cob_id, [])
        if callback in callbacks:
            callbacks.remove(callback)

    def on_state(self, callback: StateCallback) -> None:
        """``callback(connected, reason)`` on every change of the link state."""
        self._state_listeners.append(callback)

    def add_ticker(self, callback: TickCallback) -> None:
        """``callback(now)`` every ``TICK_INTERVAL`` or so (timeouts are checked there)."""
        self._tickers.append(callback)

    # -- reader thread -----------------------------------------------------------------------------------------
    def _run(self) -> None:
        while not self._stop.is_set():
            if self._bus is None:
                self._open()
                continue
            try:
                message = self._bus.recv(POLL_INTERVAL)
            except (can.CanError, OSError, ValueError) as error:
                self._link_lost(str(error))
                self._stop.wait(min(self.reconnect_interval, 0.2))  # let the other side settle before reopening
                continue
            if message is not None and not message.is_error_frame and not message.is_remote_frame:
                self._dispatch(message.arbitration_id, bytes(message.data), message.timestamp or time.time())
            now = time.monotonic()
            if now >= self._next_tick:
                self._next_tick = now + TICK_INTERVAL
                self._tick(now)

    def _open(self) -> None:
        try:
            bus = self._opener()
        except (can.CanError, OSError, ValueError, ImportError) as error:
            reason = str(error)
            if reason != self.last_error:
                log.warning("bus %s: %s", self.name, reason)
                self.last_error = reason
                self._notify(False, reason)
            self._first_attempt.set()
            self._stop.wait(self.reconnect_interval)
            return
        self._bus = bus
        self.last_error = ""
        self._connected.set()
        self._first_attempt.set()
        log.info("bus %s connected", self.name)
        self._notify(True, "connected")

    def _link_lost(self, reason: str) -> None:
        if self._drop_bus():
            log.warning("bus %s lost: %s", self.name, reason)
            self.last_error = reason
            self._notify(False, reason)

    def _drop_bus(self) -> bool:
        was_connected = self._connected.is_set()
        self._connected.clear()
        bus, self._bus = self._bus, None
        if bus is not None:
            try:
                bus.shutdown()
            except (can.CanError, OSError):
                pass
        return was_connected

    def _dispatch(self, cob_id: int, data: bytes, timestamp: float) -> None:
        for callback in tuple(self._subscribers.get(cob_id, ())):
            _safely(callback, cob_id, data, timestamp)

    def _tick(self, now: float) -> None:
        for ticker in self._tickers:
            try:
                ticker(now)
            except Exception:  # a faulty listener must not stop the bus
                log.exception("bus %s: ticker failed", self.name)

    def _notify(self, connected: bool, reason: str) -> None:
        for listener in self._state_listeners:
            try:
                listener(connected, reason)
            except Exception:
                log.exception("bus %s: state listener failed", self.name)


def _safely(callback: FrameCallback, cob_id: int, data: bytes, timestamp: float) -> None:
    try:
        callback(cob_id, data, timestamp)
    except Exception:  # a faulty listener must not stop the bus
        log.exception("frame listener failed on COB-ID %#x", cob_id)
