"""Event hub: bus and drive events from any thread, fanned out to asyncio subscribers (WebSocket clients).

Publishers (reader threads, services) call ``publish`` with a JSON-ready dict.  Each subscriber owns a bounded
asyncio queue; a subscriber that does not keep up loses its oldest events rather than stalling the bus, and is told
so by a ``{"type": "overflow"}`` event.
"""

from __future__ import annotations

import asyncio
import threading
import time
from collections.abc import Callable

QUEUE_SIZE = 1000


class Subscription:
    """One consumer of events; iterate with ``await subscription.get()``."""

    def __init__(self, hub: EventHub, loop: asyncio.AbstractEventLoop, types: set[str] | None) -> None:
        self.hub = hub
        self.loop = loop
        self.types = types
        self.queue: asyncio.Queue[dict[str, object]] = asyncio.Queue(QUEUE_SIZE)

    def _deliver(self, event: dict[str, object]) -> None:
        if self.queue.full():
            self.queue.get_nowait()
            event = {"type": "overflow", "time": time.time(), "detail": "events were dropped; the client is too slow"}
        self.queue.put_nowait(event)

    async def get(self) -> dict[str, object]:
        return await self.queue.get()

    def close(self) -> None:
        self.hub.unsubscribe(self)


class EventHub:
    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._subscriptions: list[Subscription] = []
        self._listeners: list[Callable[[dict[str, object]], None]] = []

    def subscribe(self, types: set[str] | None = None) -> Subscription:
        """Subscribe from inside a running event loop; ``types`` filters event types (None: all)."""
        subscription = Subscription(self, asyncio.get_running_loop(), types)
        with self._lock:
            self._subscriptions.append(subscription)
        return subscription

    def unsubscribe(self, subscription: Subscription) -> None:
        with self._lock:
            if subscription in self._subscriptions:
                self._subscriptions.remove(subscription)

    def wants(self, event_type: str) -> bool:
        """Whether a subscriber would receive events of this type (lets a publisher skip costly work)."""
        with self._lock:
            return any(
                subscription.types is None or event_type in subscription.types for subscription in self._subscriptions
            )

    def add_listener(self, listener: Callable[[dict[str, object]], None]) -> None:
        """A plain callback run in the publisher's thread (CLI progress, tests)."""
        with self._lock:
            self._listeners.append(listener)

    def remove_listener(self, listener: Callable[[dict[str, object]], None]) -> None:
        with self._lock:
            if listener in self._listeners:
                self._listeners.remove(listener)

    def publish(self, event: dict[str, object]) -> None:
        event.setdefault("time", time.time())
        with self._lock:
            subscriptions = list(self._subscriptions)
            listeners = list(self._listeners)
        for listener in listeners:
            listener(event)
        for subscription in subscriptions:
            if subscription.types is not None and event.get("type") not in subscription.types:
                continue
            try:
                subscription.loop.call_soon_threadsafe(subscription._deliver, event)
            except RuntimeError:  # the subscriber's loop is closed
                self.unsubscribe(subscription)
