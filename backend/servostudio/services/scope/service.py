"""The capture service: the one implementation of a capture behind the REST routes, the WebSocket progress, the CLI
and the scope page.

A capture is: check the definition against the drive (``plan``, refusals before anything is written), configure and
arm the recorder, watch it until the recording is complete, read it back, convert it (``capture``). In single mode
that is one recording; in normal and auto mode a server job records again and again until stopped, each recording
frozen (stop) while it is read and the recorder armed again after. The server keeps the latest captures in memory
by id for the page to fetch, export or save in the project (``store``).
"""

from __future__ import annotations

import itertools
import secrets
import threading
import time
from collections import OrderedDict
from collections.abc import Callable

from servostudio.drive.access import Drive
from servostudio.errors import Conflict, NotFound
from servostudio.services.bus import BusConnection, Job, JobRegistry
from servostudio.services.cancel import Cancellation, Cancelled
from servostudio.services.scope.capture import Capture, DriveIdentity, build_capture
from servostudio.services.scope.definition import CaptureDefinition
from servostudio.services.scope.plan import CapturePlan, plan_capture, recorder_of
from servostudio.services.scope.presets import presets_for
from servostudio.services.scope.recorder import POLL_SECONDS, RecorderSession, Report

#: captures the server keeps for its clients (a 4 × 2048 capture is about 0.3 MB in memory)
KEEP_CAPTURES = 16
#: how long a stop waits for the node's capture job to end (a status read or an upload part: milliseconds)
STOP_WAIT = 5.0
Node = tuple[str, int]


class UnknownCapture(NotFound):
    """No capture of that id in the server's memory (never made, or one of the oldest, forgotten)."""


class CaptureRunning(Conflict):
    """A capture job is running on the node already."""


def identity_of(connection: BusConnection, drive: Drive) -> DriveIdentity:
    """The drive as the bus's scan (or first use) identified it."""
    info = connection.nodes.get(drive.node)
    dictionary = drive.dictionary
    return DriveIdentity(
        bus=connection.id,
        node=drive.node,
        device=drive.profile.device,
        product_name=dictionary.product_name if dictionary is not None else "",
        vendor_id=info.vendor_id if info else None,
        product_code=info.product_code if info else None,
        revision=info.revision if info else None,
        serial_number=info.serial_number if info else None,
        software_version=info.software_version if info else None,
    )


def session_of(drive: Drive) -> RecorderSession:
    return RecorderSession(drive, recorder_of(drive))


def check(drive: Drive, definition: CaptureDefinition) -> CapturePlan:
    """The plan of a capture, or its refusal; reads only the recorder's read-only limits."""
    session = session_of(drive)
    return plan_capture(drive, session.recorder, session.limits(), definition)


def record_once(session: RecorderSession, plan: CapturePlan, identity: DriveIdentity, report: Report,
                cancellation: Cancellation) -> Capture:  # fmt: skip
    """Arm, wait for a complete recording, read it: one capture. The recorder must be configured for ``plan``."""
    counter = session.read("counter")
    session.command("arm")
    report({"stage": "armed"})
    session.wait_recording(plan, report, cancellation, counter)
    if plan.definition.mode != "single":
        session.command("stop")  # normal and auto re-arm at once: freeze the recording while it is read
    recording = session.upload(plan, report, cancellation)
    return build_capture(plan, recording.data, recording.trigger_record, identity)


def capture(drive: Drive, identity: DriveIdentity, definition: CaptureDefinition, report: Report | None = None,
            cancellation: Cancellation | None = None) -> Capture:  # fmt: skip
    """One capture, start to end (what the CLI does; a job does it in a loop for normal and auto mode)."""
    plan = check(drive, definition)
    session = session_of(drive)
    session.configure(plan)
    return record_once(session, plan, identity, report or _quiet, cancellation or Cancellation())


def _quiet(event: dict[str, object]) -> None:
    """No one follows this capture's progress."""


class ScopeService:
    """The server's captures: jobs per node, the latest results by id."""

    def __init__(self, keep: int = KEEP_CAPTURES) -> None:
        self.keep = keep
        self._captures: OrderedDict[str, Capture] = OrderedDict()
        self._running: dict[Node, Job] = {}
        self._numbers = itertools.count(1)
        self._lock = threading.Lock()

    def describe(self, drive: Drive) -> dict[str, object]:
        """What the page shows before a capture: the recorder's limits and the presets this drive can run."""
        session = session_of(drive)
        limits = session.limits()
        return {
            "channels": session.recorder.channels,
            "capacity": limits.capacity,
            "base_period_ns": limits.base_period_ns,
            "status": session.status(),
            "presets": [
                {
                    "key": item.key,
                    "title": item.title,
                    "description": item.description,
                    "definition": item.definition.as_dict(),
                }
                for item in presets_for(drive)
            ],
        }

    def start(self, jobs: JobRegistry, connection: BusConnection, drive: Drive, definition: CaptureDefinition) -> Job:
        """Check the definition now (a refusal is the caller's answer, not a failed job), then capture in a job."""
        plan = check(drive, definition)
        node = (connection.id, drive.node)
        identity = identity_of(connection, drive)
        with self._lock:
            running = self._running.get(node)
            if running is not None and running.state == "running":
                raise CaptureRunning(f"node {drive.node}: capture {running.id} is running; stop it first")

            def work(progress: Callable[[dict[str, object]], None], cancellation: Cancellation) -> object:
                return self._run(drive, plan, identity, _on_node(progress, node), cancellation)

            job = jobs.start("scope", work)
            self._running[node] = job
        return job

    def _run(self, drive: Drive, plan: CapturePlan, identity: DriveIdentity, report: Report,
             cancellation: Cancellation) -> dict[str, object]:  # fmt: skip
        session = session_of(drive)
        session.configure(plan)
        made: list[str] = []
        try:
            while not made or (plan.definition.mode != "single" and not cancellation.requested):
                made.append(self.remember(record_once(session, plan, identity, report, cancellation)))
                report({"stage": "captured", "capture": made[-1]})
        except Cancelled:
            if not made:
                raise  # stopped before the first recording: nothing to show
        return {"capture": made[-1], "captures": len(made), "bus": identity.bus, "node": identity.node}

    def remember(self, made: Capture) -> str:
        """Keep a capture for the clients; returns its id (unguessable: ids name data of the machine)."""
        capture_id = f"c{next(self._numbers)}-{secrets.token_hex(4)}"
        with self._lock:
            self._captures[capture_id] = made
            while len(self._captures) > self.keep:
                self._captures.popitem(last=False)
        return capture_id

    def get(self, capture_id: str) -> Capture:
        try:
            return self._captures[capture_id]
        except KeyError:
            raise UnknownCapture(f"no capture {capture_id!r} (the server keeps the latest {self.keep})") from None

    def force(self, drive: Drive) -> str:
        """Make the next sample the trigger sample (while the recorder fills or waits); the status after it."""
        session = session_of(drive)
        session.command("force")
        return session.status()

    def stop(self, bus: str, drive: Drive) -> str:
        """Stop the node's capture job (if one runs) and the recorder; the status after it. The job ends at its next
        status read or upload part: the answer waits for that (bounded), so a client sees it ended."""
        with self._lock:
            job = self._running.get((bus, drive.node))
        if job is not None:
            job.cancellation.cancel()
        session = session_of(drive)
        session.command("stop")
        deadline = time.monotonic() + STOP_WAIT
        while job is not None and job.state == "running" and time.monotonic() < deadline:
            time.sleep(POLL_SECONDS / 2)
        return session.status()

    def status(self, bus: str, drive: Drive) -> dict[str, object]:
        session = session_of(drive)
        with self._lock:
            job = self._running.get((bus, drive.node))
        running = job.id if job is not None and job.state == "running" else None
        return {"status": session.status(), "counter": session.read("counter"), "job": running}


def _on_node(progress: Callable[[dict[str, object]], None], node: Node) -> Report:
    """Scope progress events name the operation, the bus and the node (the page follows its axis's)."""
    return lambda event: progress({"type": "progress", "operation": "scope", "bus": node[0], "node": node[1], **event})
