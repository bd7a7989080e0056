"""WebSockets: ``/api/ws/events`` (bus, drive, progress and job events) and ``/api/ws/terminal`` (dialog terminal).

Events are JSON objects with a ``type``: bus_state, bus_closed, scan, emcy, bootup, nmt_state, heartbeat_lost,
heartbeat_back, drive_state, progress, job, control, control_request, motion, overflow.  While a client wants
``drive_state``, the known drives' status words are polled slowly (``services.bus.statewatch``).
``/api/ws/events?types=emcy,progress`` filters.

Terminal protocol (client → server): ``{"op": "watch", "items": [{"bus", "node", "object"}…], "period_ms": 200}``
starts continuous monitoring (``{"op": "watch", "items": []}`` stops it), ``{"op": "read", "items": […]}`` reads once,
``{"op": "write", "bus", "node", "object", "value", "physical", "client"}`` writes (``client``: the motion client
id from /api/ws/events, needed for motion: docs/motion-safety.md).  Server → client: ``{"type": "values",
"rows": [...]}``, ``{"type": "written", "value": {...}}``, ``{"type": "error", "detail", "error", "kind"}`` (the
fields of the REST error body).
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import logging
from collections.abc import Callable
from typing import Any, TypeVar

from fastapi import APIRouter, WebSocket, WebSocketDisconnect

from servostudio.api.auth import identify
from servostudio.api.deps import Access, Caller, Connections, Events, Motion
from servostudio.api.errors import error_body
from servostudio.api.security import Requires, require_message
from servostudio.errors import ServoStudioError
from servostudio.services.audit import Actor, acting_as
from servostudio.services.bus import ConnectionManager
from servostudio.services.motion import MotionGuard
from servostudio.services.terminal import TerminalError, Watch, WatchItem, sample
from servostudio.services.users import AccessControl, Level, User, check_write

router = APIRouter(tags=["events"])
log = logging.getLogger(__name__)
T = TypeVar("T")
#: the level each client message needs, checked per message with the caller as it is then (a session that ended
#: or a level lowered meanwhile applies at once); a write needs the object's own level too
TERMINAL_MESSAGES: dict[str, Level] = {"read": Level.OPERATOR, "watch": Level.OPERATOR, "write": Level.MAINTENANCE}
#: the event socket's client messages: the hold-to-run keepalive of a motion the client started (a motion needs
#: Maintenance, so its keepalive does too); anything else is read only to notice a disconnect
EVENT_MESSAGES: dict[str, Level] = {"keepalive": Level.MAINTENANCE}


@router.websocket("/ws/events", dependencies=[Requires(Level.OPERATOR)])
async def events_socket(
    socket: WebSocket,
    hub: Events,
    motion: Motion,
    manager: Connections,
    user: Caller,
    control: Access,
    types: str | None = None,
) -> None:
    """Events as they happen. The socket is also the caller's motion client: its first message,
    ``{"type": "hello", "client": ID}``, gives the id that arming an axis and every motion request must name
    (X-Servo-Client); the axes it holds get a quick stop when the socket closes.  An event addressed to one client
    (``"to"``: a ``control_request`` for the axis's holder) goes to that client only.  The client sends
    ``{"type": "keepalive", "bus", "node"}`` while it holds a hold-to-run motion (``services.motion.hold``)."""
    await socket.accept()
    client = motion.connect(user.name)
    subscription = hub.subscribe(set(types.split(",")) if types else None)
    receiver = asyncio.create_task(_drain(socket, lambda text: _client_message(text, socket, control, motion, client)))
    try:
        await socket.send_json({"type": "hello", "client": client})
        while not receiver.done():
            getter = asyncio.create_task(subscription.get())
            done, _ = await asyncio.wait({getter, receiver}, return_when=asyncio.FIRST_COMPLETED)
            if getter in done and getter.result().get("to") in (None, client):
                await socket.send_json(getter.result())
            else:
                getter.cancel()
    except (WebSocketDisconnect, RuntimeError):  # RuntimeError: sending after the client closed
        pass
    finally:
        subscription.close()
        receiver.cancel()
        motion.disconnect(client, manager)  # returns at once: the quick stops run on their own thread


async def _drain(socket: WebSocket, handle: Callable[[str], None]) -> None:
    """Read client messages until it disconnects."""
    with contextlib.suppress(WebSocketDisconnect):
        while True:
            handle(await socket.receive_text())


def _client_message(text: str, socket: WebSocket, control: AccessControl, motion: MotionGuard, client: str) -> None:
    """A keepalive keeps the client's hold-to-run motion of that axis going (at once, on the loop: it is a
    timestamp); one that is malformed, of a caller below its level, or for an axis the client holds no motion of
    keeps nothing alive, and the motion stops when its hold times out."""
    try:
        message = json.loads(text)
    except ValueError:
        return
    if not isinstance(message, dict) or message.get("type") != "keepalive":
        return
    try:
        require_message(identify(socket, control), EVENT_MESSAGES, "keepalive", "events")
        motion.keepalive(client, (str(message["bus"]), int(message["node"])))
    except (ServoStudioError, KeyError, TypeError, ValueError) as refusal:
        log.debug("keepalive of client %s ignored: %s", client, refusal)


@router.websocket("/ws/terminal", dependencies=[Requires(Level.OPERATOR)])
async def terminal_socket(socket: WebSocket, manager: Connections, motion: Motion, control: Access) -> None:
    """One request per message; a refusal is answered as an error message and the terminal stays open."""
    await socket.accept()
    terminal = _Terminal(socket, manager, motion, control)
    try:
        while True:
            await terminal.answer(await socket.receive_json())
    except WebSocketDisconnect:
        pass
    finally:
        terminal.stop_watch()


class _Terminal:
    """One terminal socket: its requests and the watch it runs."""

    def __init__(
        self, socket: WebSocket, manager: ConnectionManager, motion: MotionGuard, control: AccessControl
    ) -> None:
        self.socket, self.manager, self.motion, self.control = socket, manager, motion, control
        self.monitor: asyncio.Task | None = None

    async def answer(self, message: object) -> None:
        try:
            await self._handle(_request(message))
        except ServoStudioError as error:
            await self.socket.send_json({"type": "error", **error_body(error)})
        except WebSocketDisconnect:
            raise
        except Exception as error:  # a bug: logged, reported, and the terminal stays open
            log.exception("terminal request %r failed with an unexpected error", message)
            await self.socket.send_json(
                {"type": "error", "detail": f"internal error ({type(error).__name__})", "kind": "internal"}
            )

    async def _handle(self, message: dict) -> None:
        operation = message.get("op")
        caller = identify(self.socket, self.control)
        require_message(caller, TERMINAL_MESSAGES, str(operation), "terminal")
        if operation == "write":
            value = await asyncio.to_thread(self._write, message, caller)
            await self.socket.send_json({"type": "written", "value": value})
        elif operation in ("read", "watch"):
            watch = _watch(message)
            self.stop_watch()
            if operation == "read":
                await self.socket.send_json(
                    {"type": "values", "rows": await asyncio.to_thread(sample, self.manager, watch)}
                )
            elif watch.items:
                self.monitor = asyncio.create_task(_monitor(self.socket, self.manager, watch))
        else:
            raise TerminalError(f"unknown op {operation!r}; use read, watch or write")

    def _write(self, message: dict, caller: User) -> dict[str, object]:
        """A terminal write, at the object's level and through the motion guard like every write (``client``: the
        caller's motion client)."""
        bus, node, key = _field(message, "bus", str), _field(message, "node", int), _field(message, "object", str)
        if "value" not in message:
            raise TerminalError("missing 'value'")
        drive = self.manager.get(bus).drive(node)
        check_write(caller, drive.variable(key))
        physical = bool(message.get("physical", False))
        with acting_as(Actor(caller.name, str(caller.level), message.get("client"))):
            return drive.write(key, message["value"], physical).as_dict()

    def stop_watch(self) -> None:
        if self.monitor is not None:
            self.monitor.cancel()
            self.monitor = None


def _request(message: object) -> dict:
    if not isinstance(message, dict):
        raise TerminalError("a terminal message is a JSON object with an 'op'")
    return message


def _field(message: dict, name: str, kind: Callable[[Any], T]) -> T:
    """A required field of a terminal message, converted by ``kind`` (str, int, float)."""
    if name not in message:
        raise TerminalError(f"missing {name!r}")
    try:
        return kind(message[name])
    except (TypeError, ValueError):
        raise TerminalError(f"{name!r}: {message[name]!r} is no {getattr(kind, '__name__', kind)}") from None


def _watch(message: dict) -> Watch:
    items = message.get("items", [])
    if not isinstance(items, list):
        raise TerminalError("'items' must be a list of {bus, node, object}")
    period_ms = _field({"period_ms": 200, **message}, "period_ms", float)
    return Watch(tuple(_item(item) for item in items), period_ms / 1000)


def _item(item: object) -> WatchItem:
    if not isinstance(item, dict):
        raise TerminalError(f"a watch item is {{bus, node, object}}, not {item!r}")
    return WatchItem(_field(item, "bus", str), _field(item, "node", int), _field(item, "object", str))


async def _monitor(socket: WebSocket, manager: ConnectionManager, watch: Watch) -> None:
    while True:
        rows = await asyncio.to_thread(sample, manager, watch)
        await socket.send_json({"type": "values", "rows": rows})
        await asyncio.sleep(watch.period)
