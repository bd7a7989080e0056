"""``servostudio scope … --server URL``: the capture made by a running server (the shared communication server), the
files written here — the same files, JSON summary and exit codes as on a bus of its own.

The server checks the definition (422: exit 3, nothing armed), captures as a job, and keeps the capture by id; this
side follows the job, then fetches the capture's summary, CSV and HTML and writes the files atomically. Ctrl-C
stops the server's job and the recorder (``…/scope/stop``), as it stops the recorder of a local capture.

A roll (``--roll``) is started by ``POST …/scope/roll`` (the server checks the bus budget: 422, exit 3) and followed
on the WebSocket the answer names; every samples and gap event goes into the same ``RollRecord`` the local command
fills, so the CSV is the same. Ctrl-C sends the socket's stop message and reads on to the roll's end.
"""

from __future__ import annotations

import json
import time
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from websockets.exceptions import WebSocketException
from websockets.sync.client import ClientConnection, connect

from servostudio.cli.remote import Remote, quoted
from servostudio.cli.server_drive import ServerBus
from servostudio.errors import CommunicationError
from servostudio.formats.textfile import write_bytes_atomic
from servostudio.services.cancel import Cancellation, Cancelled
from servostudio.services.scope import CaptureDefinition, ChannelInfo, DriveIdentity
from servostudio.services.scope.rollfile import RollRecord

#: how often the job is asked while the server captures (a capture takes from milliseconds to minutes)
POLL_SECONDS = 0.05
#: how long the roll's socket may stay silent (the server sends every 10 ms while samples come)
SILENT_SECONDS = 10.0


class RemoteCaptureFailed(CommunicationError):
    """The server's capture job failed (the drive, the bus, no recording in time); its reason is the job's."""


def capture_through(
    bus: ServerBus, node: int, definition: CaptureDefinition, cancellation: Cancellation
) -> dict[str, Any]:
    """The result of the server's capture job for ``definition`` (``capture``: its id; ``arm``, ``arm_note`` for
    several axes by their recorders); a cancel stops the server's job and recorder."""
    scope = bus.path(node, "/scope")
    job = bus.call("POST", f"{scope}/captures", definition.as_dict())
    while job["state"] == "running":
        if cancellation.requested:
            bus.call("POST", f"{scope}/stop")
            raise Cancelled(f"node {node}: capture stopped through {bus.remote.url}")
        time.sleep(POLL_SECONDS)
        job = bus.call("GET", f"/api/jobs/{quoted(job['id'])}")
    if job["state"] == "cancelled":
        raise Cancelled(f"node {node}: the server's capture job {job['id']} was stopped")
    if job["state"] != "done":
        raise RemoteCaptureFailed(f"node {node}: {job['error'] or 'the capture failed'} (server job {job['id']})")
    return dict(job["result"])


def write_files(bus: ServerBus, node: int, capture_id: str, out: Path, html: Path | None) -> dict[str, Any]:
    """The server's capture as the local command writes it: the CSV (and HTML) atomically, and its summary."""
    path = bus.path(node, f"/scope/captures/{quoted(capture_id)}")
    made = bus.call("GET", path)
    write_bytes_atomic(out, bus.remote.exchange("GET", f"{path}/csv")[0])
    if html is not None:
        write_bytes_atomic(html, bus.remote.exchange("GET", f"{path}/html")[0])
    return {
        "out": str(out),
        "html": str(html) if html is not None else None,
        "node": made["drive"]["node"],
        "channels": [channel["key"] for channel in made["channels"]],
        "samples": made["samples"],
        "period_us": made["period_ns"] / 1000,
        "trigger": made["trigger"],
        "trigger_index": made["trigger_index"],
        "captured": made["captured_at"],
        "source": made["source"],
        "alignment_ns": made["alignment_ns"],
    }


def roll_through(bus: ServerBus, node: int, definition: CaptureDefinition, seconds: float,
                 cancellation: Cancellation) -> RollRecord:  # fmt: skip
    """The server's roll of ``seconds``, every sample and gap its socket sent; a cancel stops the roll early."""
    body = {"channels": list(definition.channels), "period_us": definition.period_us, "seconds": seconds}
    started = bus.call("POST", bus.path(node, "/scope/roll"), body)
    plan = started["plan"]
    record = RollRecord(tuple(ChannelInfo(**channel) for channel in plan["channels"]), plan["period_ns"],
                        DriveIdentity(bus.bus, node, ""), _now())  # fmt: skip
    try:
        with connect(_socket_url(bus.remote, started["socket"]), additional_headers=_auth(bus.remote),
                     max_size=2**24) as socket:  # fmt: skip
            end = _follow_roll(socket, record, cancellation)
    except (WebSocketException, OSError) as error:
        raise RemoteCaptureFailed(f"node {node}: the roll's socket failed: {error}") from None
    if "error" in end:
        raise RemoteCaptureFailed(f"node {node}: {end['error']} (server job {started['job']['id']})")
    record.drive = DriveIdentity(**end["drive"])
    return record


def _follow_roll(socket: ClientConnection, record: RollRecord, cancellation: Cancellation) -> dict[str, Any]:
    """Events into ``record`` until the roll's ``end`` (returned); the stop message once cancelled."""
    stopping, silent_since = False, time.monotonic()
    while True:
        if cancellation.requested and not stopping:
            socket.send(json.dumps({"type": "stop"}))
            stopping = True
        try:
            event = json.loads(socket.recv(timeout=POLL_SECONDS * 4))
        except TimeoutError:
            if time.monotonic() - silent_since > SILENT_SECONDS:
                raise RemoteCaptureFailed(f"the roll's socket was silent for {SILENT_SECONDS:g} s") from None
            continue
        silent_since = time.monotonic()
        if event["type"] == "end":
            return dict(event)
        record.take(event)


def _socket_url(remote: Remote, path: str) -> str:
    """The socket's URL on the server's: ``http`` → ``ws``, ``https`` → ``wss``."""
    scheme, _, rest = remote.url.partition("://")
    socket_scheme = {"http": "ws", "https": "wss"}.get(scheme.lower(), scheme)
    return f"{socket_scheme}://{rest.rstrip('/')}{path}"


def _auth(remote: Remote) -> dict[str, str]:
    return {"Authorization": f"Bearer {remote.token}"} if remote.token else {}


def _now() -> str:
    return datetime.now(UTC).isoformat(timespec="seconds").replace("+00:00", "Z")
