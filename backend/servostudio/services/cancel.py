"""Cancellation of a long operation (backup, restore, commission) by its client.

The operation stops at the next object or file boundary: transfers not yet started are dropped, the one on the
wire completes, so the report says exactly what was done.  Files are written only whole, so a cancelled backup
leaves no half-written file.
"""

from __future__ import annotations

import threading
from collections.abc import Callable


class Cancelled(Exception):
    """The operation was cancelled before it completed."""


class Cancellation:
    """Set once by whoever cancels; the operation checks it, or registers a callback to drop queued work."""

    def __init__(self) -> None:
        self._event = threading.Event()
        self._lock = threading.Lock()
        self._callbacks: list[Callable[[], None]] = []

    @property
    def requested(self) -> bool:
        return self._event.is_set()

    def cancel(self) -> None:
        with self._lock:
            self._event.set()
            callbacks, self._callbacks = self._callbacks, []
        for callback in callbacks:
            callback()

    def on_cancel(self, callback: Callable[[], None]) -> Callable[[], None]:
        """Run ``callback`` when cancelled (at once if already); returns a function that unregisters it."""
        with self._lock:
            if not self._event.is_set():
                self._callbacks.append(callback)
                return lambda: self._forget(callback)
        callback()
        return lambda: None

    def _forget(self, callback: Callable[[], None]) -> None:
        with self._lock:
            if callback in self._callbacks:
                self._callbacks.remove(callback)

    def check(self, what: str) -> None:
        """Raise Cancelled (naming ``what`` was not done) if cancellation was requested."""
        if self._event.is_set():
            raise Cancelled(f"cancelled before {what}")
