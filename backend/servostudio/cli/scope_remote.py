"""``servostudio scope … --server URL``: the capture made by a running server (the shared communication server), the
files written here — the same files, JSON summary and exit codes as on a bus of its own.

The server checks the definition (422: exit 3, nothing armed), captures as a job, and keeps the capture by id; this
side follows the job, then fetches the capture's summary, CSV and HTML and writes the files atomically. Ctrl-C
stops the server's job and the recorder (``…/scope/stop``), as it stops the recorder of a local capture.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

from servostudio.cli.remote import quoted
from servostudio.cli.server_drive import ServerBus
from servostudio.errors import CommunicationError
from servostudio.formats.textfile import write_bytes_atomic
from servostudio.services.cancel import Cancellation, Cancelled
from servostudio.services.scope import CaptureDefinition

#: how often the job is asked while the server captures (a capture takes from milliseconds to minutes)
POLL_SECONDS = 0.05


class RemoteCaptureFailed(CommunicationError):
    """The server's capture job failed (the drive, the bus, no recording in time); its reason is the job's."""


def capture_through(bus: ServerBus, node: int, definition: CaptureDefinition, cancellation: Cancellation) -> str:
    """The id of the capture the server made for ``definition``; a cancel stops the server's job and recorder."""
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
    return str(job["result"]["capture"])


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
