"""Sequences as the server offers them: one monitor per axis, kept while clients watch it."""

from __future__ import annotations

import threading

from servostudio.drive.access import Drive
from servostudio.errors import NotFound
from servostudio.services.bus import BusConnection
from servostudio.services.motion import Axis
from servostudio.services.sequences import memory
from servostudio.services.sequences.monitor import SequenceMonitor


class NoMonitor(NotFound):
    """Nobody started the monitor of this axis."""


class SequenceMonitors:
    """The live monitors of the server's axes (at most one per axis; a start while one runs reuses it)."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._monitors: dict[Axis, SequenceMonitor] = {}

    def start(self, connection: BusConnection, drive: Drive, fresh: bool = False) -> SequenceMonitor:
        """The axis's monitor, started now if there is none (``fresh``: a new one, with an empty timeline)."""
        axis = (connection.id, drive.node)
        with self._lock:
            running = self._monitors.get(axis)
        if running is not None and not fresh:
            return running
        monitor = SequenceMonitor(connection, drive, memory.upload(drive))  # the table, for the loop counter
        with self._lock:
            previous, self._monitors[axis] = self._monitors.get(axis), monitor
        if previous is not None:
            previous.stop()
        try:
            return monitor.start()
        except BaseException:
            with self._lock:
                if self._monitors.get(axis) is monitor:
                    del self._monitors[axis]
            raise

    def get(self, axis: Axis) -> SequenceMonitor:
        with self._lock:
            monitor = self._monitors.get(axis)
        if monitor is None:
            raise NoMonitor(f"node {axis[1]} on bus {axis[0]}: no sequence monitor runs; start it first")
        return monitor

    def stop(self, axis: Axis) -> None:
        with self._lock:
            monitor = self._monitors.pop(axis, None)
        if monitor is not None:
            monitor.stop()

    def close(self) -> None:
        with self._lock:
            monitors, self._monitors = list(self._monitors.values()), {}
        for monitor in monitors:
            monitor.stop()
