"""WebSockets: ``/api/ws/events`` (bus, drive, progress and job events) and ``/api/ws/terminal`` (dialog terminal).

Events are JSON objects with a ``type``: bus_state, bus_closed, scan, emcy, bootup, nmt_state, heartbeat_lost,
heartbeat_back, drive_state, progress, job, overflow.  While a client wants ``drive_state``, the known drives'
status words are polled slowly (``services.bus.statewatch``).  ``/api/ws/events?types=emcy,progress`` filters.

Terminal protocol (client → server): ``{"op": "watch", "items": [{"bus", "node", "object"}…], "period_ms": 200}``
starts continuous monitoring (``{"op": "watch", "items": []}`` stops it), ``{"op": "read", "items": […]}`` reads once,
``{"op": "write", "bus", "node", "object", "value", "physical", "client"}`` writes (``client``: the motion client
id from /api/ws/events, needed for a control word that enables operation).  Server → client: ``{"type": "values",
"rows": [...]}``, ``{"type": "written", "value": {...}}``, ``{"type": "error", "detail": "..."}``.
"""

from __future__ import annotations

import asyncio
import contextlib

from fastapi import APIRouter, Depends, WebSocket, WebSocketDisconnect

from servostudio.api.deps import User, current_user, get_connections, get_events, get_motion
from servostudio.services.bus import ConnectionManager, EventHub
from servostudio.services.motion import MotionGuard
from servostudio.services.terminal import TerminalError, Watch, WatchItem, sample, write

router = APIRouter(tags=["events"])


@router.websocket("/ws/events")
async def events_socket(
    socket: WebSocket,
    types: str | None = None,
    user: User = Depends(current_user),
    hub: EventHub = Depends(get_events),
    motion: MotionGuard = Depends(get_motion),
    manager: ConnectionManager = Depends(get_connections),
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
async def terminal_socket(
    socket: WebSocket,
    user: User = Depends(current_user),
    manager: ConnectionManager = Depends(get_connections),
    motion: MotionGuard = Depends(get_motion),
) -> None:
    await socket.accept()
    monitor: asyncio.Task | None = None
    try:
        while True:
            message = await socket.receive_json()
            try:
                operation = message.get("op")
                if operation == "write":
                    value = await asyncio.to_thread(
                        write,
                        manager,
                        motion,
                        message.get("client"),
                        message["bus"],
                        int(message["node"]),
                        str(message["object"]),
                        message["value"],
                        bool(message.get("physical", False)),
                    )
                    await socket.send_json({"type": "written", "value": value})
                elif operation in ("read", "watch"):
                    watch = _watch(message)
                    if monitor is not None:
                        monitor.cancel()
                        monitor = None
                    if operation == "read":
                        rows = await asyncio.to_thread(sample, manager, watch)
                        await socket.send_json({"type": "values", "rows": rows})
                    elif watch.items:
                        monitor = asyncio.create_task(_monitor(socket, manager, watch))
                else:
                    raise TerminalError(f"unknown op {operation!r}; use read, watch or write")
            except (TerminalError, LookupError, ValueError, TypeError, KeyError) as error:
                await socket.send_json({"type": "error", "detail": str(error)})
            except Exception as error:  # SDO errors and the like: reported, the terminal stays open
                await socket.send_json({"type": "error", "detail": str(error)})
    except WebSocketDisconnect:
        pass
    finally:
        if monitor is not None:
            monitor.cancel()


def _watch(message: dict) -> Watch:
    items = tuple(
        WatchItem(str(item["bus"]), int(item["node"]), str(item["object"])) for item in message.get("items", [])
    )
    return Watch(items, float(message.get("period_ms", 200)) / 1000)


async def _monitor(socket: WebSocket, manager: ConnectionManager, watch: Watch) -> None:
    while True:
        rows = await asyncio.to_thread(sample, manager, watch)
        await socket.send_json({"type": "values", "rows": rows})
        await asyncio.sleep(watch.period)
