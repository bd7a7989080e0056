"""Live roll mode (docs/scope.md §8): up to 4 channels per axis streamed without end through synchronous TPDOs at the
server's SYNC, sequence-numbered, to whoever follows the roll (the scope page's WebSocket, the CLI).

Sample *k* of a run is the *k*-th frame of every borrowed TPDO, as in a TPDO capture (`stream.TpdoStream`, whose
set-up and write-back the roll shares). CAN delivers frames in order and repeats a damaged one itself, so samples
are lost only when the bus or a drive stops: the link drops (the SYNC cannot be sent) or some TPDO leaves a SYNC
unanswered for ``LOSS_SECONDS``. Either ends the run; the roll waits for the link, lets late frames pass, and
starts a new run whose first sequence number is the SYNC slot of that instant (``start + seq × period``) — the
numbers in between are a gap, reported as such, never filled. "Record while rolling" keeps every sample up to the
first gap (a capture's samples are contiguous) and at most ``MAX_SAMPLES``.
"""

from __future__ import annotations

import json
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, replace
from itertools import islice
from threading import Lock

from servostudio.drive.access import Drive
from servostudio.drive.link import BusLink
from servostudio.drive.sync import SyncProducer
from servostudio.services.cancel import Cancellation
from servostudio.services.scope.capture import ChannelInfo
from servostudio.services.scope.definition import CaptureDefinition, split_channel
from servostudio.services.scope.plan import CaptureRefused
from servostudio.services.scope.recorder import Report
from servostudio.services.scope.stream import TAKE_SECONDS, Column, StreamResult, TpdoStream, _Receiver
from servostudio.services.scope.stream_plan import MAX_SAMPLES, Bus, StreamPlan, plan_stream
from servostudio.services.scope.window import Sample

#: channels per axis a roll streams at most
ROLL_CHANNELS = 4
#: a SYNC some TPDO has not answered for this long is lost: a drive answers within a period or two, and frames a
#: busy host reads late are still whole — only a silence this long is a drive or bus gone
LOSS_SECONDS = 1.0
#: after a run ended, frames of its last SYNCs may still arrive: the roll waits them out before counting again
SETTLE_SECONDS = 0.05
#: how long the roll looks for a lost link at a time (the cancel and the end are checked in between)
RECONNECT_SECONDS = 0.5
#: events a feed keeps for a slow reader (at one batch per ``TAKE_SECONDS``: 30 s)
FEED_EVENTS = 3000
Event = dict[str, object]


def roll_plan(drive: Drive, axes: Callable[[int], Drive], definition: CaptureDefinition, bitrate: int | None,
              seconds: float | None) -> StreamPlan:  # fmt: skip
    """The roll's plan — its channels in the TPDOs, its frames/s and bus load against the bit rate — or the
    refusal (``CaptureRefused``: 422, exit 3) before anything is written: more than 4 channels on an axis, a
    period below 1 ms, a bus load beyond 70 %."""
    per_node: dict[int, int] = {}
    for channel in definition.channels:
        node = split_channel(channel)[1] or drive.node
        per_node[node] = per_node.get(node, 0) + 1
        if per_node[node] > ROLL_CHANNELS:
            raise CaptureRefused(f"roll mode streams up to {ROLL_CHANNELS} channels per axis")
    samples = MAX_SAMPLES if seconds is None else max(2, min(MAX_SAMPLES, round(seconds * 1e6 / definition.period_us)))
    rolling = replace(definition, samples=samples, duration_s=None, source="tpdo", mode="single", timeout_s=None)
    return plan_stream(drive, axes, rolling, Bus(bitrate), "tpdo")


@dataclass
class _Entry:
    """An event of the feed and its JSON text, encoded by the first reader that sends it, for every reader."""

    event: Event
    text: str | None = None

    def encoded(self) -> tuple[Event, str]:
        if self.text is None:
            self.text = encode(self.event)
        return self.event, self.text


def encode(event: Event) -> str:
    """An event as the roll's socket sends it: compact JSON, as Starlette's ``send_json`` spells it."""
    return json.dumps(event, separators=(",", ":"), ensure_ascii=False)


class RollFeed:
    """The roll's events for its readers, each with its own cursor; a reader too slow for ``keep`` events is told
    what it missed (a gap), never given a silent hole. An endless roll (no ``seconds``) is there for its readers:
    when the last one leaves (a closed tab, a lost network), ``join`` says so and the roll is stopped."""

    def __init__(self, keep: int = FEED_EVENTS, endless: bool = False) -> None:
        self._events: deque[_Entry] = deque(maxlen=keep)
        self._count = 0
        self._lock = Lock()
        self.ended = False
        self.endless = endless
        self._readers = 0

    def join(self, delta: int) -> bool:
        """A reader came (+1) or left (−1); True when an endless roll has none left."""
        with self._lock:
            self._readers += delta
            return self.endless and self._readers == 0 and not self.ended

    def put(self, event: Event) -> None:
        with self._lock:
            self._events.append(_Entry(event))
            self._count += 1
            self.ended = self.ended or event["type"] == "end"

    def since(self, cursor: int) -> tuple[list[tuple[Event, str]], int]:
        """The events after the first ``cursor`` ones, each with its JSON text (`encode`: once for all readers,
        outside the lock the roll puts its events under), and the new cursor."""
        with self._lock:
            first = self._count - len(self._events)
            fresh = list(islice(self._events, max(cursor - first, 0), None))
            count = self._count
        missed: Event = {"type": "gap", "reason": f"this client fell behind: {first - cursor} batches dropped"}
        return ([(missed, encode(missed))] if cursor < first else []) + [entry.encoded() for entry in fresh], count


@dataclass
class _Gated(_Receiver):
    """A TPDO's frames from ``open_at`` on (of its mapping's length, as every receiver takes them): an answer to a
    SYNC before the run (the probe of the nodes' state, a run that ended) may arrive late and would shift every
    sample by one."""

    open_at: float = 0.0

    def on_frame(self, cob_id: int, data: bytes, timestamp: float) -> None:
        if time.monotonic() >= self.open_at:
            super().on_frame(cob_id, data, timestamp)


@dataclass
class _Run:
    """One run of the SYNC producer: its first sequence number and the samples delivered so far."""

    base: int
    sync: SyncProducer
    delivered: int = 0
    progress_at: float = 0.0


class RollStream(TpdoStream):
    """The roll of the plan's channels until cancelled or ``seconds`` passed; events go to ``feed``."""

    def __init__(self, plan: StreamPlan, axes: Callable[[int], Drive], link: BusLink, feed: Callable[[Event], None],
                 seconds: float | None = None, record: bool = False) -> None:  # fmt: skip
        super().__init__(plan, axes, link)
        self.gated = [_Gated(receiver.use, receiver.layout) for receiver in self.receivers]
        self.receivers = [*self.gated]
        self.feed, self.record = feed, record
        self.total = None if seconds is None else round(seconds * 1e9 / plan.period_ns)
        self.taken = 0  # frames dropped from the receivers' lists after delivery
        self.recorded: list[Sample] = []
        self.recording = record
        self.gaps: list[tuple[int, int, str]] = []  # sequence numbers [from, to) lost, and why
        self.samples = 0
        self.jitter_ns = 0
        self.channels = [ChannelInfo.of(channel.variable) for channel in plan.channels]
        self._wall = time.time() - time.monotonic()

    def _capture(self, report: Report, cancellation: Cancellation) -> StreamResult:
        origin, base = time.monotonic(), 0
        report({"stage": "rolling"})
        while not self._ended(base, cancellation):
            self._open()
            run = _Run(base, SyncProducer(self.link, self.plan.period_ns / 1e9, self._answered).start())
            try:
                reason = self._follow(run, cancellation)
            finally:
                run.sync.stop()
                self.jitter_ns = max(self.jitter_ns, run.sync.jitter_ns())
            if reason is None:
                break
            base = self._recover(run, reason, origin, cancellation)
        return StreamResult(tuple(zip(*self.recorded, strict=True)), 0, self.jitter_ns)

    def _open(self) -> None:
        """Count frames from now on (the run's first SYNC follows)."""
        now = time.monotonic()
        for receiver in self.gated:
            receiver.open_at = now
            receiver.frames.clear()
        self.taken = 0

    def _ended(self, seq: int, cancellation: Cancellation) -> bool:
        return cancellation.requested or (self.total is not None and seq >= self.total)

    def _answered(self) -> int:
        return self.taken + min(len(receiver.frames) for receiver in self.receivers)

    def _follow(self, run: _Run, cancellation: Cancellation) -> str | None:
        """Deliver the samples of one run; None when the roll ends, else why samples were lost."""
        run.progress_at = time.monotonic()
        while True:
            self._deliver(run)
            if self._ended(run.base + run.delivered, cancellation):
                return None
            if run.sync.error is not None:
                return f"link lost: {run.sync.error}"
            if run.sync.count > self._answered() and time.monotonic() - run.progress_at > LOSS_SECONDS:
                return f"SYNC unanswered for {LOSS_SECONDS:g} s by {self._silent()}"
            time.sleep(TAKE_SECONDS)

    def _deliver(self, run: _Run) -> None:
        complete = self._answered() - self.taken
        if self.total is not None:
            complete = min(complete, self.total - run.base - run.delivered)
        if complete <= 0:
            return
        columns = self._columns(0, complete)
        for receiver in self.receivers:
            del receiver.frames[:complete]
        self.taken += complete
        # an answer may arrive before its SYNC's send instant is noted (the latest instant then), and after a cut link
        # late answers of the previous run before the new producer noted any instant (now, then)
        instants = run.sync.sent or [time.monotonic()]
        last = len(instants) - 1
        sent = instants[min(run.delivered, last)], instants[min(run.delivered + complete - 1, last)]
        self.feed(self._batch(run.base + run.delivered, columns, sent))
        self._keep(columns)
        run.delivered += complete
        run.progress_at = time.monotonic()

    def _batch(self, seq: int, columns: list[Column], sent: tuple[float, float]) -> Event:
        count = len(columns[0])
        self.samples += count
        values = [info.physical_all(column) for info, column in zip(self.channels, columns, strict=True)]
        return {"type": "samples", "seq": seq, "count": count, "values": values,
                "synced_at": [sent[0] + self._wall, sent[1] + self._wall]}  # fmt: skip

    def _keep(self, columns: list[Column]) -> None:
        if self.recording:
            room = MAX_SAMPLES - len(self.recorded)
            self.recorded += zip(*(column[:room] for column in columns), strict=True)
            self.recording = len(self.recorded) < MAX_SAMPLES

    def _silent(self) -> str:
        answered = self._answered() - self.taken
        nodes = sorted({receiver.use.node for receiver in self.receivers if len(receiver.frames) <= answered})
        return ", ".join(f"node {node}" for node in nodes)

    def _recover(self, run: _Run, reason: str, origin: float, cancellation: Cancellation) -> int:
        """After lost samples: the link back, late frames let pass; the gap reported; the next run's first number."""
        lost_from = run.base + run.delivered
        while not self._ended(lost_from, cancellation) and not self.link.wait_connected(RECONNECT_SECONDS):
            pass
        time.sleep(SETTLE_SECONDS)
        resume = max(lost_from, round((time.monotonic() - origin) * 1e9 / self.plan.period_ns))
        resume = resume if self.total is None else min(resume, self.total)
        self.gaps.append((lost_from, resume, reason))
        self.feed({"type": "gap", "from": lost_from, "to": resume, "reason": reason})
        self.recording = False
        return resume

    def summary(self) -> Event:
        """What the roll delivered: samples, the gaps (sequence numbers lost and why), the SYNC's jitter."""
        return {
            "samples": self.samples,
            "gaps": [{"from": start, "to": end, "reason": reason} for start, end, reason in self.gaps],
            "lost": sum(end - start for start, end, _ in self.gaps),
            "recorded": len(self.recorded),
            "jitter_ns": self.jitter_ns,
        }
