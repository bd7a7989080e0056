"""The capture service: the one implementation of a capture behind the REST routes, the WebSocket progress, the CLI
and the scope page.

A capture is: check the definition against the drive (``plan``, refusals before anything is written), configure and
arm the recorder, watch it until the recording is complete, read it back, convert it (``capture``). In single mode
that is one recording; in normal and auto mode a server job records again and again until stopped, each recording
frozen (stop) while it is read and the recorder armed again after. A drive without a recorder, channels of several
axes, or a definition that asks for it, is captured through synchronous TPDOs at the server's SYNC, or by polling
(``stream_plan``, ``stream``). The server keeps the latest captures in memory by id for the page to fetch, export or
save in the project (``store``).
"""

from __future__ import annotations

import itertools
import secrets
import threading
import time
from collections import OrderedDict
from collections.abc import Callable
from dataclasses import asdict, replace
from datetime import UTC, datetime

from servostudio.drive.access import Drive
from servostudio.drive.sync import MIN_PERIOD_S
from servostudio.drive.tpdo import tpdo_slots
from servostudio.errors import NotFound
from servostudio.services.bus import BusConnection, Job, JobRegistry
from servostudio.services.cancel import Cancellation, Cancelled
from servostudio.services.scope.capture import Capture, ChannelInfo, DriveIdentity, build_capture
from servostudio.services.scope.definition import CaptureDefinition, split_channel
from servostudio.services.scope.multi import MultiPlan, MultiRecorderCapture, plan_multi
from servostudio.services.scope.plan import CapturePlan, CaptureRefused, plan_capture, recorder_of
from servostudio.services.scope.presets import presets_for
from servostudio.services.scope.recorder import POLL_SECONDS, RecorderSession, Report
from servostudio.services.scope.roll import RollFeed, RollStream, roll_plan
from servostudio.services.scope.rollfile import RollRecord
from servostudio.services.scope.stream import PollStream, StreamResult, TpdoStream
from servostudio.services.scope.stream_plan import Axes, Bus, StreamPlan, plan_stream

#: captures the server keeps for its clients (a 4 × 2048 capture is about 0.3 MB in memory)
KEEP_CAPTURES = 16
#: roll feeds the server keeps (a finished roll's last events stay readable for a while)
KEEP_FEEDS = 8
#: how long a stop waits for the node's capture job to end (a status read or an upload part: milliseconds)
STOP_WAIT = 5.0
Node = tuple[str, int]


class UnknownCapture(NotFound):
    """No capture of that id in the server's memory (never made, or one of the oldest, forgotten)."""


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


def own_channels(drive: Drive, definition: CaptureDefinition) -> bool:
    """Are all the channels the drive's own (none ``OBJ@NODE`` of another axis)?"""
    return all(split_channel(channel)[1] in (None, drive.node) for channel in definition.channels)


def by_recorder(drive: Drive, definition: CaptureDefinition) -> bool:
    """Does this capture use the drives' recorders? Asked for (one axis or several), or (auto) one drive that has
    one."""
    if definition.source == "recorder":
        return True
    return definition.source == "auto" and own_channels(drive, definition) and drive.profile.recorder is not None


def check(drive: Drive, definition: CaptureDefinition, axes: Axes | None = None,
          bitrate: int | None = None) -> CapturePlan | StreamPlan | MultiPlan:  # fmt: skip
    """The plan of a capture, or its refusal; reads only read-only objects (the recorder's limits; a poll plan
    times one round of reads). ``axes`` gives the other nodes of the bus (channels ``OBJ@NODE``)."""
    if by_recorder(drive, definition) and not own_channels(drive, definition):
        return plan_multi(drive, axes or _alone(drive), definition)
    if by_recorder(drive, definition):
        session = session_of(drive)
        return plan_capture(drive, session.recorder, session.limits(), definition)
    return plan_stream(drive, axes or _alone(drive), definition, Bus(bitrate), definition.source)


def _alone(drive: Drive) -> Axes:
    def axis(node: int) -> Drive:
        raise CaptureRefused(f"channel of node {node}: this capture reaches node {drive.node} only")

    return axis


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
            cancellation: Cancellation | None = None, axes: Axes | None = None,
            bitrate: int | None = None, operational: Callable[[int], bool] | None = None) -> Capture:  # fmt: skip
    """One capture, start to end (what the CLI does; a job does it in a loop for normal and auto mode).
    ``operational`` says which nodes are OPERATIONAL (a recorder capture of several axes starts the others for its
    broadcast arm and puts them back to PRE-OPERATIONAL; unknown: none is)."""
    plan = check(drive, definition, axes, bitrate)
    report, cancellation = report or _quiet, cancellation or Cancellation()
    if isinstance(plan, StreamPlan):
        return stream_once(drive, plan, identity, report, cancellation, axes)
    if isinstance(plan, MultiPlan):
        run = MultiRecorderCapture(plan, drive.engine.link, operational or _not_operational, bitrate)
        return run.run(report, cancellation, identity)
    session = session_of(drive)
    session.configure(plan)
    return record_once(session, plan, identity, report, cancellation)


def stream_once(drive: Drive, plan: StreamPlan, identity: DriveIdentity, report: Report,
                cancellation: Cancellation, axes: Axes | None) -> Capture:  # fmt: skip
    """A capture through TPDOs or by polling (the plan says which)."""
    reach = _reach(drive, plan, axes)
    if plan.source == "tpdo":
        result = TpdoStream(plan, reach, drive.engine.link).run(report, cancellation)
    else:
        result = PollStream(plan, reach).run(report, cancellation)
    return streamed_capture(plan, result, identity)


def roll(drive: Drive, identity: DriveIdentity, definition: CaptureDefinition, seconds: float,
         cancellation: Cancellation, axes: Axes | None = None, bitrate: int | None = None) -> RollRecord:  # fmt: skip
    """A roll of ``seconds`` (or until cancelled), start to end, every sample and gap kept (the CLI's ``--roll``);
    refused (``CaptureRefused``) before anything is written when the bus cannot carry it."""
    plan = roll_plan(drive, axes or _alone(drive), definition, bitrate, seconds)
    channels = tuple(replace(ChannelInfo.of(channel.variable), key=channel.key) for channel in plan.channels)
    record = RollRecord(channels, plan.period_ns, identity, _now())
    RollStream(plan, _reach(drive, plan, axes), drive.engine.link, record.take, seconds).run(_quiet, cancellation)
    return record


def _not_operational(node: int) -> bool:
    """A node whose NMT state is not known is taken as not OPERATIONAL (started, and put back after)."""
    return False


def _now() -> str:
    return datetime.now(UTC).isoformat(timespec="seconds").replace("+00:00", "Z")


def _reach(drive: Drive, plan: StreamPlan, axes: Axes | None) -> Axes:
    """Each node of the plan's drive (the capture's own node is ``drive``)."""
    reach = axes or _alone(drive)
    return {node: drive if node == drive.node else reach(node) for node in plan.nodes}.__getitem__


def streamed_capture(plan: StreamPlan, result: StreamResult, identity: DriveIdentity) -> Capture:
    trigger = plan.definition.trigger
    variable = plan.trigger_variable
    source = None if variable is None else plan.channels[plan.trigger_channel or 0].key
    return Capture(
        definition=plan.definition,
        channels=tuple(replace(ChannelInfo.of(channel.variable), key=channel.key) for channel in plan.channels),
        period_ns=plan.period_ns,
        trigger_index=result.trigger_index,
        trigger=type(trigger)(source, trigger.edge, trigger.level).describe(variable.unit if variable else ""),
        columns=result.columns,
        drive=identity,
        captured_at=_now(),
        source=plan.source,
        alignment_ns=result.alignment_ns,
    )


def _quiet(event: dict[str, object]) -> None:
    """No one follows this capture's progress."""


class ScopeService:
    """The server's captures: jobs per node, the latest results by id."""

    def __init__(self, keep: int = KEEP_CAPTURES) -> None:
        self.keep = keep
        self._captures: OrderedDict[str, Capture] = OrderedDict()
        self._running: dict[Node, Job] = {}
        self._feeds: OrderedDict[str, RollFeed] = OrderedDict()
        self._leads: dict[str, tuple[Job, Drive]] = {}  # the trigger drive of each triggered multi-axis capture
        self._numbers = itertools.count(1)
        self._lock = threading.Lock()

    def describe(self, drive: Drive) -> dict[str, object]:
        """What the page shows before a capture: the recorder's limits (or the TPDO capture's, for a drive without
        one) and the presets this drive can run."""
        return {**self._source_of(drive), "presets": self._presets(drive)}

    def _source_of(self, drive: Drive) -> dict[str, object]:
        if drive.profile.recorder is None:
            slots = tpdo_slots(drive.dictionary) if drive.dictionary is not None else []
            return {
                "source": "tpdo" if slots else "poll",
                "channels": min(4, 2 * len(slots)) if slots else 4,
                "capacity": None,
                "base_period_ns": round(MIN_PERIOD_S * 1e9),
                "status": "idle",
            }
        session = session_of(drive)
        limits = session.limits()
        return {
            "source": "recorder",
            "channels": session.recorder.channels,
            "capacity": limits.capacity,
            "base_period_ns": limits.base_period_ns,
            "status": session.status(),
        }

    def _presets(self, drive: Drive) -> list[dict[str, object]]:
        return [
            {
                "key": item.key,
                "title": item.title,
                "description": item.description,
                "definition": item.definition.as_dict(),
            }
            for item in presets_for(drive)
        ]

    def start(self, jobs: JobRegistry, connection: BusConnection, drive: Drive, definition: CaptureDefinition) -> Job:
        """Check the definition now (a refusal is the caller's answer, not a failed job), then capture in a job. The
        job holds every node whose channels it captures."""
        plan = check(drive, definition, connection.drive, connection.spec.bitrate)
        node = (connection.id, drive.node)
        identity = identity_of(connection, drive)

        def work(progress: Callable[[dict[str, object]], None], cancellation: Cancellation) -> object:
            if isinstance(plan, MultiPlan):
                operational = lambda other: connection.nmt_state(other) == "OPERATIONAL"  # noqa: E731
                return self._run_axes(drive, plan, identity, _on_node(progress, node), cancellation, operational,
                                      connection.spec.bitrate)  # fmt: skip
            return self._run(drive, plan, identity, _on_node(progress, node), cancellation, connection.drive)

        nodes = plan.nodes if isinstance(plan, StreamPlan | MultiPlan) else (drive.node,)
        sync = isinstance(plan, StreamPlan) and plan.source == "tpdo"
        job = self._claim(connection, nodes, lambda: jobs.start("scope", work), sync)
        if isinstance(plan, MultiPlan) and plan.triggered:  # a force is the trigger drive's: the others follow it
            with self._lock:
                self._leads = {key: lead for key, lead in self._leads.items() if lead[0].state == "running"}
                self._leads[job.id] = (job, plan.axes[0].drive)
        return job

    def _claim(self, connection: BusConnection, nodes: tuple[int, ...], start: Callable[[], Job],
               sync: bool = False) -> Job:  # fmt: skip
        """Start a job that holds ``nodes`` and, through TPDOs, the bus's SYNC — refused with 409 naming the job (a
        capture, a roll, a frequency response …) that holds one of them (the bus's claims, ``services/bus/claims.py``);
        the scope's own jobs are noted per node for ``stop`` and ``status``."""
        job = connection.claims.start(nodes, start, sync)
        with self._lock:
            self._running.update(dict.fromkeys(((connection.id, node) for node in nodes), job))
        return job

    def start_roll(self, jobs: JobRegistry, connection: BusConnection, drive: Drive, definition: CaptureDefinition,
                   seconds: float | None, record: bool) -> tuple[Job, StreamPlan]:  # fmt: skip
        """Check the roll (its bus budget above all: refused before anything is armed), then roll in a job whose
        samples the feed of the job's id serves (``feed``); recorded, the samples become a capture at the end."""
        plan = roll_plan(drive, connection.drive, definition, connection.spec.bitrate, seconds)
        identity, feed = identity_of(connection, drive), RollFeed(endless=seconds is None)
        node = (connection.id, drive.node)

        def work(progress: Callable[[dict[str, object]], None], cancellation: Cancellation) -> object:
            stream = RollStream(plan, _reach(drive, plan, connection.drive), drive.engine.link, feed.put, seconds,
                                record)  # fmt: skip
            return self._roll(stream, identity, _on_node(progress, node), cancellation, feed)

        job = self._claim(connection, plan.nodes, lambda: jobs.start("scope-roll", work), sync=True)
        with self._lock:
            self._feeds[job.id] = feed
            while len(self._feeds) > KEEP_FEEDS:
                self._feeds.popitem(last=False)
        return job, plan

    def _roll(self, stream: RollStream, identity: DriveIdentity, report: Report, cancellation: Cancellation,
              feed: RollFeed) -> dict[str, object]:  # fmt: skip
        try:
            result = stream.run(report, cancellation)
        except Exception as error:
            feed.put({"type": "end", "error": str(error)})
            raise
        summary: dict[str, object] = {**stream.summary(), "bus": identity.bus, "node": identity.node,
                                      "drive": asdict(identity)}  # fmt: skip
        if result.columns:
            summary["capture"] = self.remember(streamed_capture(stream.plan, result, identity))
        feed.put({"type": "end", **summary})
        return summary

    def feed(self, roll: str) -> RollFeed:
        """The samples of a roll job (the latest few rolls are kept)."""
        try:
            return self._feeds[roll]
        except KeyError:
            raise UnknownCapture(f"no roll {roll!r} (the server keeps the latest {KEEP_FEEDS})") from None

    def _run(self, drive: Drive, plan: CapturePlan | StreamPlan, identity: DriveIdentity, report: Report,
             cancellation: Cancellation, axes: Axes) -> dict[str, object]:  # fmt: skip
        if isinstance(plan, StreamPlan):
            streamed = self.remember(stream_once(drive, plan, identity, report, cancellation, axes))
            report({"stage": "captured", "capture": streamed})
            return {"capture": streamed, "captures": 1, "bus": identity.bus, "node": identity.node}
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

    def _run_axes(self, drive: Drive, plan: MultiPlan, identity: DriveIdentity, report: Report,
                  cancellation: Cancellation, operational: Callable[[int], bool],
                  bitrate: int | None = None) -> dict[str, object]:  # fmt: skip
        """A recorder capture of several axes; the result says how the recorders were armed."""
        run = MultiRecorderCapture(plan, drive.engine.link, operational, bitrate)
        made = self.remember(run.run(report, cancellation, identity))
        report({"stage": "captured", "capture": made})
        assert run.armed is not None
        return {"capture": made, "captures": 1, "bus": identity.bus, "node": identity.node, "arm": run.armed.method,
                "alignment_ns": run.armed.alignment_ns, "arm_note": run.armed.note}  # fmt: skip

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

    def force(self, drive: Drive, bus: str | None = None) -> str:
        """Make the next sample the trigger sample (while the recorder fills or waits); the status after it. In a
        triggered capture of several axes running on the node it is the trigger drive's recorder that is forced
        (the others follow it, as they follow its trigger)."""
        with self._lock:
            job = self._running.get((bus, drive.node)) if bus is not None else None
        lead = self._leads.get(job.id) if job is not None and job.state == "running" else None
        session = session_of(lead[1] if lead is not None else drive)
        session.command("force")
        return session.status()

    def stop(self, bus: str, drive: Drive) -> str:
        """Stop the node's capture job (if one runs) and the recorder; the status after it. The job ends at its next
        status read or upload part: the answer waits for that (bounded), so a client sees it ended."""
        with self._lock:
            job = self._running.get((bus, drive.node))
        if job is not None:
            job.cancellation.cancel()
        if drive.profile.recorder is not None:
            session_of(drive).command("stop")
        deadline = time.monotonic() + STOP_WAIT
        while job is not None and job.state == "running" and time.monotonic() < deadline:
            time.sleep(POLL_SECONDS / 2)
        return self.status(bus, drive)["status"]  # type: ignore[return-value]

    def status(self, bus: str, drive: Drive) -> dict[str, object]:
        with self._lock:
            job = self._running.get((bus, drive.node))
        running = job.id if job is not None and job.state == "running" else None
        if drive.profile.recorder is None:  # the server assembles the capture: its job is the status
            return {"status": "recording" if running else "idle", "counter": 0, "job": running}
        session = session_of(drive)
        return {"status": session.status(), "counter": session.read("counter"), "job": running}


def _on_node(progress: Callable[[dict[str, object]], None], node: Node) -> Report:
    """Scope progress events name the operation, the bus and the node (the page follows its axis's)."""
    return lambda event: progress({"type": "progress", "operation": "scope", "bus": node[0], "node": node[1], **event})
