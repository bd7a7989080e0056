"""One CAN bus as the drive layer sees it: a reader thread, frame dispatch by COB-ID, sends, reconnection.

python-can's Notifier stops for good on the first receive error; a communication server must instead report
the loss, keep serving other buses, and reopen the interface when it comes back.  ``BusLink`` owns the bus
object: while the link is up a single reader thread receives frames and hands them to the subscribers of their
COB-ID; when a receive or send fails the link goes down (listeners are told why), the bus is closed, and the
thread tries to reopen it every ``reconnect_interval`` seconds.

Frames that arrive together are dispatched as one batch. While the reader thread dispatches a batch, what its
callbacks send is held back and leaves in one write at the end of the batch (the follow-up requests of several
drives reach the bus together); then the ``after_dispatch`` callbacks run, so slower bookkeeping (completing
futures, converting values) never delays a request.
"""

from __future__ import annotations

import contextlib
import logging
import threading
import time
from collections.abc import Callable

import can

from servostudio.errors import Unavailable

log = logging.getLogger(__name__)

FrameCallback = Callable[[int, bytes, float], None]
StateCallback = Callable[[bool, str], None]
TickCallback = Callable[[float], None]
TICK_INTERVAL = 0.01
POLL_INTERVAL = 0.02


class LinkDownError(Unavailable, ConnectionError):
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
        self._after_dispatch: list[Callable[[], None]] = []
        self._held: list[tuple[int, bytes]] | None = None  # sends of the reader thread during a batch
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
        """Stop the reader and close the interface, then tell the listeners the link is down: the transfers waiting
        on it fail at once (no reader thread is left to answer or time them out)."""
        self._stop.set()
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join(timeout=2.0)
        self._drop_bus()
        self.last_error = "closed"
        self._notify(False, "closed")

    @property
    def closed(self) -> bool:
        return self._stop.is_set()

    @property
    def connected(self) -> bool:
        return self._connected.is_set()

    def wait_connected(self, timeout: float) -> bool:
        return self._connected.wait(timeout)

    # -- frames ------------------------------------------------------------------------------------------------
    def check_connected(self) -> None:
        """Raise `LinkDownError` (saying why) unless the link is up: for a sender that waits between its frames
        (the SYNC producer held back by its consumers), whose next send would come too late to tell of a cut."""
        if not self.connected:
            raise self._down()

    def _down(self) -> LinkDownError:
        if self.closed:
            return LinkDownError(f"bus {self.name} was closed")
        detail = f" ({self.last_error})" if self.last_error else ""
        return LinkDownError(f"bus {self.name} is not connected{detail}")

    def send(self, cob_id: int, data: bytes) -> None:
        bus = self._bus
        if bus is None or not self.connected:
            raise self._down()
        if self._held is not None and threading.current_thread() is self._thread:
            self._held.append((cob_id, data))  # leaves with the rest of the batch's answers
            return
        self._send_now(bus, [(cob_id, data)])

    def _send_now(self, bus: can.BusABC, frames: list[tuple[int, bytes]]) -> None:
        try:
            with self._send_lock:
                _write(bus, frames)
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

    def after_dispatch(self, callback: Callable[[], None]) -> None:
        """``callback()`` on the reader thread after each batch of received frames was dispatched and the sends
        it caused went out."""
        self._after_dispatch.append(callback)

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
                self._receive(self._bus)
            except (can.CanError, OSError, ValueError) as error:
                self._link_lost(str(error))
                self._stop.wait(min(self.reconnect_interval, 0.2))  # let the other side settle before reopening
                continue
            now = time.monotonic()
            if now >= self._next_tick:
                self._next_tick = now + TICK_INTERVAL
                self._tick(now)

    def _receive(self, bus: can.BusABC) -> None:
        """Dispatch what arrives within ``POLL_INTERVAL``: every frame at once from our own buses
        (``receive_frames``), else one python-can message."""
        receive_frames = getattr(bus, "receive_frames", None)
        if receive_frames is not None:
            frames = receive_frames(POLL_INTERVAL)
        else:
            message = bus.recv(POLL_INTERVAL)
            frames = (
                []
                if message is None or message.is_error_frame or message.is_remote_frame
                else [(message.arbitration_id, bytes(message.data), message.timestamp, message.is_extended_id)]
            )
        if not frames:
            return
        self._held = []
        try:
            for cob_id, data, timestamp, _extended in frames:
                self._dispatch(cob_id, data, timestamp or time.time())
        finally:
            held, self._held = self._held, None
        if held:
            try:
                self._send_now(bus, held)
            except LinkDownError:
                return  # the listeners were told; the transfers waiting for these frames fail with the link
        for callback in self._after_dispatch:
            _safely_call(callback)

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
        """The reason is recorded before the link reads as down, so whoever sees it down (`check_connected`, a
        send) is told why."""
        if self._connected.is_set():
            self.last_error = reason
        if self._drop_bus():
            log.warning("bus %s lost: %s", self.name, reason)
            self._notify(False, reason)

    def _drop_bus(self) -> bool:
        was_connected = self._connected.is_set()
        self._connected.clear()
        bus, self._bus = self._bus, None
        if bus is not None:
            with contextlib.suppress(can.CanError, OSError):
                bus.shutdown()
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


def _write(bus: can.BusABC, frames: list[tuple[int, bytes]]) -> None:
    """Send standard data frames, all in one write where the bus can (``send_frames``), without building python-can
    Messages where it offers ``send_frame``."""
    if len(frames) > 1 and hasattr(bus, "send_frames"):
        bus.send_frames(frames)
        return
    send_frame = getattr(bus, "send_frame", None)
    for cob_id, data in frames:
        if send_frame is not None:
            send_frame(cob_id, data)
        else:
            bus.send(can.Message(arbitration_id=cob_id, data=data, is_extended_id=False))


def _safely_call(callback: Callable[[], None]) -> None:
    try:
        callback()
    except Exception:  # a faulty listener must not stop the bus
        log.exception("after-dispatch callback failed")


def _safely(callback: FrameCallback, cob_id: int, data: bytes, timestamp: float) -> None:
    try:
        callback(cob_id, data, timestamp)
    except Exception:  # a faulty listener must not stop the bus
        log.exception("frame listener failed on COB-ID %#x", cob_id)
