"""Motion needs a live client: an axis a client enabled is quick-stopped when that client goes away.

A browser (or script) holds the event WebSocket open while it works; the socket is its *motion client*. Enabling
an axis names that client, which then owns the axis until the axis is switched to another state. When the socket
closes — tab closed, network gone, laptop asleep — every axis it owns gets a quick stop.
"""

from __future__ import annotations

import logging
import secrets
import threading

from servostudio.drive.access import Drive
from servostudio.drive.cia402 import Command, State
from servostudio.drive.control import set_state
from servostudio.drive.object_values import ObjectValue
from servostudio.errors import RefusedForSafety, ServoStudioError
from servostudio.services.bus import ConnectionManager

log = logging.getLogger(__name__)

Axis = tuple[str, int]  # (bus id, node)

#: Control-word bits that select the device-control command (fault reset, enable operation … switch on).
_COMMAND_MASK = 0x8F


class NoLiveClient(RefusedForSafety, PermissionError):
    """Motion was asked for without a connected client to answer for it."""


class MotionGuard:
    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._owned: dict[str, set[Axis]] = {}

    def connect(self) -> str:
        """A new live client; its id is sent to it and comes back with every motion request."""
        client = secrets.token_hex(8)
        with self._lock:
            self._owned[client] = set()
        return client

    def claim(self, client: str | None, axis: Axis) -> None:
        """`client` takes responsibility for `axis` (about to be enabled); refused without a live client."""
        with self._lock:
            if client not in self._owned:
                raise NoLiveClient(
                    "enabling a drive needs a live client: keep /api/ws/events open and send the "
                    "client id it announced in the X-Servo-Client header"
                )
            for axes in self._owned.values():
                axes.discard(axis)
            self._owned[client].add(axis)

    def write(
        self, client: str | None, axis: Axis, drive: Drive, key: str, value: object, physical: bool = False
    ) -> ObjectValue:
        """Write one object of an axis: the way every object write of the server goes (REST, terminal), so a
        control word that enables operation cannot pass without `client`."""
        self.check_controlword_write(client, axis, drive, key, value)
        return drive.write(key, value, physical)

    def change_state(self, client: str | None, axis: Axis, drive: Drive, target: State) -> None:
        """Walk the axis to `target`: enabling claims it for `client` (refused without one), any other target
        releases it."""
        if target is State.OPERATION_ENABLED:
            self.claim(client, axis)
        else:
            self.release(axis)
        set_state(drive, target)

    def check_controlword_write(self, client: str | None, axis: Axis, drive: Drive, key: str, value: object) -> None:
        """A raw write that enables operation is motion like any other: claim the axis for `client` (or refuse)."""
        if not drive.profile.has("controlword") or drive.variable(key).key != drive.profile.address("controlword"):
            return
        controlword = _integer(value)
        if controlword is None:
            return  # not a number: the write itself refuses it with the dictionary's message
        if controlword & _COMMAND_MASK == Command.ENABLE_OPERATION:
            self.claim(client, axis)
        else:
            self.release(axis)

    def release(self, axis: Axis) -> None:
        """The axis left Operation enabled on purpose: nobody owns it any more."""
        with self._lock:
            for axes in self._owned.values():
                axes.discard(axis)

    def disconnect(self, client: str, manager: ConnectionManager) -> threading.Thread | None:
        """The client is gone: quick-stop every axis it owns, on a thread of its own (returned, already started;
        None when it owned none).

        Not on the event loop's executor: the socket handler calling this may itself be cancelled (server shutdown,
        a test client tearing its loop down), and the axes must stop all the same."""
        with self._lock:
            axes = sorted(self._owned.pop(client, set()))
        if not axes:
            return None
        stopper = threading.Thread(target=self._quick_stop, args=(client, axes, manager), name=f"motion-stop {client}")
        stopper.start()
        return stopper

    @staticmethod
    def _quick_stop(client: str, axes: list[Axis], manager: ConnectionManager) -> None:
        for bus, node in axes:
            try:
                set_state(manager.get(bus).drive(node), State.QUICK_STOP_ACTIVE)
                log.warning("client %s went away: quick stop of node %d on bus %s", client, node, bus)
            except ServoStudioError as error:
                log.error("client %s went away: quick stop of node %d on bus %s failed: %s", client, node, bus, error)
            except Exception:  # a bug must not leave the other axes running
                log.exception("client %s went away: quick stop of node %d on bus %s failed", client, node, bus)


def _integer(value: object) -> int | None:
    """A control word as the caller spelled it (number or decimal/0x text); None when it is no integer."""
    try:
        if isinstance(value, str):
            return int(value, 0)
        if isinstance(value, int | float):
            return int(value)
    except (ValueError, OverflowError):
        pass
    return None
