"""WebSockets: ``/api/ws/events`` (bus, drive, progress and job events) and ``/api/ws/terminal`` (dialog terminal).

Events are JSON objects with a ``type``: bus_state, bus_closed, scan, emcy, bootup, nmt_state, heartbeat_lost,
heartbeat_back, drive_state, progress, job, overflow.  While a client wants ``drive_state``, the known drives'
status words are polled slowly (``services.bus.statewatch``).  ``/api/ws/events?types=emcy,progress`` filters.

Terminal protocol (client → server): ``{"op": "watch", "items": [{"bus", "node", "object"}…], "period_ms": 200}``
starts continuous monitoring (``{"op": "watch", "items": []}`` stops it), ``{"op": "read", "items": […]}`` reads once,
``{"op": "write", "bus", "node", "object", "value", "physical", "client"}`` writes (``client``: the motion client
id from /api/ws/events, needed for a control word that enables operation).  Server → client: ``{"type": "values",
"rows": [...]}``, ``{"type": "written", "value": {...}}``, ``{"type": "error", "detail", "error", "kind"}`` (the
fields of the REST error body).
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
from collections.abc import Callable
from typing import Any, TypeVar

from fastapi import APIRouter, Depends, WebSocket, WebSocketDisconnect

from servostudio.api.deps import Connections, Events, Motion, current_user
from servostudio.api.errors import error_body
from servostudio.errors import ServoStudioError
from servostudio.services.bus import ConnectionManager
from servostudio.services.motion import MotionGuard
from servostudio.services.terminal import TerminalError, Watch, WatchItem, sample

router = APIRouter(tags=["events"], dependencies=[Depends(current_user)])
log = logging.getLogger(__name__)
T = TypeVar("T")


@router.websocket("/ws/events")
async def events_socket(
    socket: WebSocket, hub: Events, motion: Motion, manager: Connections, types: str | None = None
) -> None:
    """Events as they happen. The socket is also the caller's motion client: its first message,
    ``{"type": "hello", "client": ID}``, gives the id that enabling a drive must name (X-Servo-Client), and the
    axes it enabled get a quick stop when the socket closes."""
    await socket.accept()
    client = motion.connect()
    subscription = hub.subscribe(set(types.split(",")) if types else None)
    receiver = asyncio.create_task(_drain(socket))
    try:
        await socket.send_json({"type": "hello", "client": client})
        while not receiver.done():
            getter = asyncio.create_task(subscription.get())
            done, _ = await asyncio.wait({getter, receiver}, return_when=asyncio.FIRST_COMPLETED)
            if getter in done:
                await socket.send_json(getter.result())
            else:
                getter.cancel()
    except (WebSocketDisconnect, RuntimeError):  # RuntimeError: sending after the client closed
        pass
    finally:
        subscription.close()
        receiver.cancel()
        motion.disconnect(client, manager)  # returns at once: the quick stops run on their own thread


async def _drain(socket: WebSocket) -> None:
    """Read (and ignore) client messages until it disconnects."""
    with contextlib.suppress(WebSocketDisconnect):
        while True:
            await socket.receive_text()


@router.websocket("/ws/terminal")
async def terminal_socket(socket: WebSocket, manager: Connections, motion: Motion) -> None:
    """One request per message; a refusal is answered as an error message and the terminal stays open."""
    await socket.accept()
    terminal = _Terminal(socket, manager, motion)
    try:
        while True:
            await terminal.answer(await socket.receive_json())
    except WebSocketDisconnect:
        pass
    finally:
        terminal.stop_watch()


class _Terminal:
    """One terminal socket: its requests and the watch it runs."""

    def __init__(self, socket: WebSocket, manager: ConnectionManager, motion: MotionGuard) -> None:
        self.socket, self.manager, self.motion = socket, manager, motion
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
        if operation == "write":
            value = await asyncio.to_thread(self._write, message)
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

    def _write(self, message: dict) -> dict[str, object]:
        """A terminal write, through the motion guard like every write (``client``: the caller's motion client)."""
        bus, node, key = _field(message, "bus", str), _field(message, "node", int), _field(message, "object", str)
        if "value" not in message:
            raise TerminalError("missing 'value'")
        drive = self.manager.get(bus).drive(node)
        physical = bool(message.get("physical", False))
        return self.motion.write(message.get("client"), (bus, node), drive, key, message["value"], physical).as_dict()

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
