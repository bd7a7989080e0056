"""One controller per axis: live clients, and the axis each one has armed.

A *live client* is an open event WebSocket (or a running CLI command): it exists only while someone is there to
answer for the machine.  A client *arms* an axis to become its controller — the one client whose motion writes
the axis accepts — and *releases* it to disarm.  Another client sees who holds it and may *request* it (the holder
is asked over its event socket) or, with the Expert level, *take it over*.  When a client goes away it holds
nothing any more: the guard quick-stops what it held (``guard.MotionGuard.disconnect``).
"""

from __future__ import annotations

import secrets
import threading
import time
from dataclasses import dataclass, field

from servostudio.errors import Conflict, RefusedForSafety
from servostudio.services.audit import Actor

Axis = tuple[str, int]  # (bus id, node)


class NoLiveClient(RefusedForSafety, PermissionError):
    """Motion was asked for without a connected client to answer for it."""


class AxisHeld(RefusedForSafety):
    """Another client is the axis's controller; the message names it."""


class NotArmed(RefusedForSafety):
    """The caller has a live client but has not armed the axis."""


class NotHeld(Conflict):
    """A request or a release for an axis nobody (or somebody else) holds."""


@dataclass(frozen=True)
class Holder:
    """A live client as others see it: its id, its user and since when it holds what it holds."""

    client: str
    user: str
    since: float = field(default_factory=time.time)

    def as_dict(self) -> dict[str, object]:
        return {"client": self.client, "user": self.user, "since": self.since}

    def __str__(self) -> str:
        return f"client {self.client} (user {self.user})"


def where(axis: Axis) -> str:
    return f"node {axis[1]} on bus {axis[0]}"


class Controllers:
    """The live clients, and the one controller of each armed axis (thread-safe)."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._clients: dict[str, str] = {}  # client id → user
        self._held: dict[Axis, Holder] = {}
        self._requests: dict[Axis, dict[str, Holder]] = {}

    def connect(self, user: str) -> str:
        """A new live client of ``user``; its id is sent to it and comes back with every motion request."""
        client = secrets.token_hex(8)
        with self._lock:
            self._clients[client] = user
        return client

    def disconnect(self, client: str) -> list[Axis]:
        """The client is gone: it holds nothing and asks for nothing any more; returns the axes it held."""
        with self._lock:
            self._clients.pop(client, None)
            lost = sorted(axis for axis, holder in self._held.items() if holder.client == client)
            for axis in lost:
                del self._held[axis]
            for asked in self._requests.values():
                asked.pop(client, None)
        return lost

    def holder(self, axis: Axis) -> Holder | None:
        with self._lock:
            return self._held.get(axis)

    def requests(self, axis: Axis) -> list[Holder]:
        with self._lock:
            return list(self._requests.get(axis, {}).values())

    def held(self) -> dict[Axis, Holder]:
        with self._lock:
            return dict(self._held)

    def live(self, actor: Actor) -> Holder:
        """The actor's live client, or the refusal that says how to get one."""
        with self._lock:
            return self._live(actor)

    def _live(self, actor: Actor, why: str = "") -> Holder:
        if actor.client is None or self._clients.get(actor.client) != actor.user:
            said = f"{why}: " if why else ""
            raise NoLiveClient(
                f"{said}motion needs the axis's armed controller, a live client: keep /api/ws/events open, arm the "
                "axis with the client id it announced (X-Servo-Client) and send that id with every motion request"
            )
        return Holder(actor.client, actor.user)

    def arm(self, actor: Actor, axis: Axis) -> bool:
        """The actor's client becomes the axis's controller, unless another client holds it; False when it was
        already."""
        with self._lock:
            mine = self._live(actor)
            holder = self._held.get(axis)
            if holder is not None and holder.client != mine.client:
                raise self.held_by(axis, holder)
            if holder is not None:
                return False
            self._held[axis] = mine
            self._requests.pop(axis, None)
            return True

    def release(self, actor: Actor, axis: Axis) -> Holder:
        """The controller disarms the axis; returns who held it."""
        with self._lock:
            holder = self._held.get(axis)
            if holder is None or holder.client != actor.client:
                raise NotHeld(f"{where(axis)} is not armed by this client: nothing to release")
            del self._held[axis]
            return holder

    def request(self, actor: Actor, axis: Axis) -> Holder:
        """The actor asks for an axis someone else holds; returns the holder, who is to be asked."""
        with self._lock:
            mine = self._live(actor)
            holder = self._held.get(axis)
            if holder is None or holder.client == mine.client:
                raise NotHeld(f"{where(axis)} is not held by another client: arm it instead")
            self._requests.setdefault(axis, {})[mine.client] = mine
            return holder

    def take_over(self, actor: Actor, axis: Axis) -> Holder | None:
        """The actor's client becomes the controller whoever held the axis; returns the previous holder."""
        with self._lock:
            mine = self._live(actor)
            previous = self._held.get(axis)
            self._held[axis] = mine
            self._requests.pop(axis, None)
            return previous

    def require_controller(self, actor: Actor, axis: Axis, why: str) -> None:
        """Motion: only the axis's armed controller, through its live client."""
        with self._lock:
            holder = self._held.get(axis)
            if holder is not None and holder.client != actor.client:
                raise self.held_by(axis, holder, why)
            self._live(actor, why)
            if holder is None:
                raise NotArmed(
                    f"{why}: arm {where(axis)} first (POST …/control/arm) — motion needs an armed controller"
                )

    def require_free_or_controller(self, actor: Actor, axis: Axis, why: str) -> None:
        """Setting up motion: anyone while nobody holds the axis, else only its controller."""
        with self._lock:
            holder = self._held.get(axis)
            if holder is not None and holder.client != actor.client:
                raise self.held_by(axis, holder, why)

    @staticmethod
    def held_by(axis: Axis, holder: Holder, why: str = "") -> AxisHeld:
        said = f"{why}: " if why else ""
        return AxisHeld(
            f"{said}{where(axis)} is armed by {holder}: ask for it (POST …/control/request) or, with the Expert "
            "level, take it over (POST …/control/take-over)"
        )
