"""Captures without the drive's recorder, run (docs/scope.md §7): synchronous TPDOs at the server's SYNC, or SDO
polling; one or several axes of one bus.

TPDO: the TPDOs the plan borrows are read first (their configuration is written back at the end, whatever
happens), mapped with the channels and sent at every SYNC; a node that is not OPERATIONAL (no TPDO answers a first
SYNC) is started and put back to PRE-OPERATIONAL afterwards. Then the server's SYNC producer runs: sample *k* is
the *k*-th frame of every borrowed TPDO — all drives of the bus sample at the same SYNC frame, so the axes are
aligned to the sample. Polling reads every channel at each period instead (the axes in parallel).

Both feed a `SampleWindow` (pre-trigger and trigger as the recorder has them) until it is complete, the timeout
passes or the client cancels; nothing is kept from an incomplete capture.
"""

from __future__ import annotations

import struct
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field

from servostudio.drive.access import Drive
from servostudio.drive.link import BusLink
from servostudio.drive.nmt import NmtCommand, send_nmt
from servostudio.drive.sync import SYNC_COB_ID, SyncProducer, announce_cycle, restore_cycle
from servostudio.drive.tpdo import TpdoConfig, read_tpdo, synchronous, write_tpdo
from servostudio.errors import CommunicationError, ServoStudioError
from servostudio.services.cancel import Cancellation, Cancelled
from servostudio.services.scope.capture import FORMATS
from servostudio.services.scope.recorder import NoTrigger, Report
from servostudio.services.scope.stream_plan import StreamPlan, TpdoUse
from servostudio.services.scope.window import Sample, SampleWindow

#: how often the capture thread takes the frames received (the reader thread only appends them)
TAKE_SECONDS = 0.01
#: how long a first SYNC waits for the TPDOs of OPERATIONAL nodes
PROBE_SECONDS = 0.1
#: after the probe, how long no frame may come before the capture's SYNCs start (a late answer to the probe would
#: otherwise be taken for sample 0), and how many such waits at most
QUIET_SECONDS = 0.05
QUIET_TRIES = 20
Column = tuple[int | float, ...]
Columns = tuple[Column, ...]


class StreamFailed(CommunicationError):
    """The capture's frames stopped (link lost, SYNC producer stopped, a drive silent); nothing was kept."""


@dataclass(frozen=True)
class StreamResult:
    columns: Columns
    trigger_index: int
    alignment_ns: int  # the largest distance of a sample from its instant: SYNC jitter, or a poll's read time


@dataclass
class _Receiver:
    """The frames of one borrowed TPDO, appended by the bus reader thread."""

    use: TpdoUse
    layout: struct.Struct
    frames: list[bytes] = field(default_factory=list)

    def on_frame(self, cob_id: int, data: bytes, timestamp: float) -> None:
        """A frame of another length is the TPDO's former mapping, sent before the new one took effect (an event
        TPDO of the status word while the drive was enabled): not a sample."""
        if len(data) == self.layout.size:
            self.frames.append(bytes(data))


class TpdoStream:
    """One TPDO capture of the plan's nodes (``axes`` gives each node's drive)."""

    def __init__(self, plan: StreamPlan, axes: Callable[[int], Drive], link: BusLink) -> None:
        self.plan, self.axes, self.link = plan, axes, link
        self.saved: list[tuple[Drive, TpdoConfig]] = []
        self.started: list[int] = []  # nodes this capture made OPERATIONAL
        self.cycles: list[tuple[Drive, int | None]] = []  # each node's 0x1006 before the capture announced its own
        self.receivers = [_Receiver(use, _layout(plan, use)) for use in plan.tpdos]
        self.subscribed: list[tuple[int, _Receiver]] = []

    def run(self, report: Report, cancellation: Cancellation) -> StreamResult:
        """The capture; the borrowed TPDOs are written back in any case (a failure to do so is said)."""
        try:
            self._configure()
            result = self._capture(report, cancellation)
        except (ServoStudioError, Cancelled) as error:
            left = self._restore()
            if left is None:
                raise
            raise StreamFailed(f"{error}; {left}") from error
        left = self._restore()
        if left is not None:
            raise StreamFailed(f"the capture completed, but {left}; nothing was kept")
        return result

    def _configure(self) -> None:
        """Save every borrowed TPDO before anything is written, then map the channels and subscribe."""
        for use in self.plan.tpdos:
            drive = self.axes(use.node)
            self.saved.append((drive, read_tpdo(drive, use.slot)))
        self._announce_cycle()
        for (drive, saved), receiver in zip(self.saved, self.receivers, strict=True):
            variables = [self.plan.channels[n].variable for n in receiver.use.channels]
            config = synchronous(saved, variables)
            write_tpdo(drive, config)
            self.link.subscribe(config.identifier, receiver.on_frame)
            self.subscribed.append((config.identifier, receiver))
        self._make_operational()

    def _announce_cycle(self) -> None:
        """The SYNC period into each node's 0x1006 (put back after): a drive that synchronises its cycle to the SYNC
        then samples one period apart however late the server's SYNC thread is (docs/scope.md §7)."""
        for node in dict.fromkeys(use.node for use in self.plan.tpdos):
            drive = self.axes(node)
            self.cycles.append((drive, announce_cycle(drive, self.plan.period_ns / 1e9)))

    def _make_operational(self) -> None:
        """One SYNC: the nodes whose TPDOs answer are OPERATIONAL; the others are started (and stopped after)."""
        self.link.send(SYNC_COB_ID, b"")
        time.sleep(PROBE_SECONDS)
        silent = {receiver.use.node for receiver in self.receivers if not receiver.frames}
        for node in sorted(silent):
            send_nmt(self.link, NmtCommand.START, node)
            self.started.append(node)
        time.sleep(PROBE_SECONDS if silent else 0)
        self._settle()

    def _settle(self) -> None:
        """Drop the answers to the probe until none comes for ``QUIET_SECONDS``: no SYNC is sent meanwhile, so every
        frame is a late answer, and one left in would be sample 0 of its TPDO — every sample of it one SYNC early.
        A node thought silent whose answer came late was OPERATIONAL: it is not put back to PRE-OPERATIONAL after."""
        for attempt in range(QUIET_TRIES):
            late = {receiver.use.node for receiver in self.receivers if receiver.frames}
            self.started = [node for node in self.started if node not in late]
            for receiver in self.receivers:
                receiver.frames.clear()
            if attempt > 0 and not late:
                return
            time.sleep(QUIET_SECONDS)

    def _capture(self, report: Report, cancellation: Cancellation) -> StreamResult:
        plan = self.plan
        window = SampleWindow(plan.depth, plan.pre_trigger, plan.trigger_channel, plan.trigger_level,
                              plan.trigger_edge)  # fmt: skip
        sync = SyncProducer(self.link, plan.period_ns / 1e9, self._answered).start()
        report({"stage": "armed"})
        try:
            _follow(window, lambda: self._take(window), report, cancellation, plan, lambda: sync.error)
        finally:
            sync.stop()
        return StreamResult(window.columns(len(plan.channels)), window.trigger_index or 0, sync.jitter_ns())

    def _answered(self) -> int:
        """The SYNCs every borrowed TPDO has answered (the producer keeps at most a few ahead of them)."""
        return min(len(receiver.frames) for receiver in self.receivers)

    def _take(self, window: SampleWindow) -> bool:
        """The samples every TPDO has delivered since the last take, into the window."""
        return window.add_all(list(zip(*self._columns(window.seen, self._answered()), strict=True)))

    def _columns(self, start: int, stop: int) -> list[Column]:
        """Samples ``start`` to ``stop`` (exclusive) of every TPDO, one column per channel of the plan, in its order."""
        columns: list[Column] = [()] * len(self.plan.channels)
        for receiver in self.receivers:
            decoded = frame_columns(receiver.layout, receiver.frames[start:stop])
            for position, column in zip(receiver.use.channels, decoded, strict=True):
                columns[position] = column
        return columns

    def _restore(self) -> str | None:
        """Every borrowed TPDO back as it was, the started nodes back to PRE-OPERATIONAL (each tried); what could
        not be done, or None."""
        for identifier, receiver in self.subscribed:
            self.link.unsubscribe(identifier, receiver.on_frame)
        failures: list[str] = []
        for drive, saved in self.saved:
            try:
                write_tpdo(drive, saved)
            except ServoStudioError as error:
                failures.append(f"node {drive.node} TPDO {saved.slot.number + 1}: {error}")
        for drive, cycle in self.cycles:
            try:
                restore_cycle(drive, cycle)
            except ServoStudioError as error:
                failures.append(f"node {drive.node} communication cycle period: {error}")
        for node in self.started:
            try:
                send_nmt(self.link, NmtCommand.PRE_OPERATIONAL, node)
            except ServoStudioError as error:
                failures.append(f"node {node} left OPERATIONAL: {error}")
        return f"the drives' TPDO configuration could not be written back ({'; '.join(failures)})" if failures else None


def _layout(plan: StreamPlan, use: TpdoUse) -> struct.Struct:
    return struct.Struct("<" + "".join(FORMATS[plan.channels[n].variable.data_type] for n in use.channels))


def frame_columns(layout: struct.Struct, frames: list[bytes]) -> list[Column]:
    """One TPDO's frames (each of ``layout.size`` bytes) as one column per value it maps: the frames joined and
    unpacked record after record and transposed in C, not a Python ``unpack`` and a tuple per frame (a roll of 3
    axes at 1 kHz decodes 3,000 frames a second)."""
    columns = list(zip(*layout.iter_unpack(b"".join(frames)), strict=True))
    return columns or [() for _ in layout.unpack(bytes(layout.size))]


def _follow(
    window: SampleWindow,
    take: Callable[[], bool],
    report: Report,
    cancellation: Cancellation,
    plan: StreamPlan,
    failed: Callable[[], str | None],
) -> None:
    """Take samples into the window until it is complete; report each stage; cancel, timeout and a failure end it."""
    deadline = None if plan.definition.timeout_s is None else time.monotonic() + plan.definition.timeout_s
    shown = ""
    while not take():
        if window.stage != shown:
            shown = window.stage
            report({"stage": shown})
        if cancellation.requested:
            raise Cancelled("capture stopped before it completed")
        if (error := failed()) is not None:
            raise StreamFailed(f"the capture's SYNC stopped: {error}; nothing was kept")
        if deadline is not None and time.monotonic() > deadline:
            raise NoTrigger(
                f"node {plan.node}: no complete capture within {plan.definition.timeout_s:g} s "
                f"({window.stage}, {window.seen} samples received); the TPDOs were restored"
            )
        time.sleep(TAKE_SECONDS)
    report({"stage": "done"})


class PollStream:
    """A polled capture: every channel read by SDO once per period, the nodes in parallel."""

    def __init__(self, plan: StreamPlan, axes: Callable[[int], Drive]) -> None:
        self.plan, self.axes = plan, axes
        self.lateness = 0.0

    def run(self, report: Report, cancellation: Cancellation) -> StreamResult:
        plan = self.plan
        window = SampleWindow(plan.depth, plan.pre_trigger, plan.trigger_channel, plan.trigger_level,
                              plan.trigger_edge)  # fmt: skip
        reader = _Poller(plan, self.axes)
        report({"stage": "armed"})
        thread = threading.Thread(target=reader.run, daemon=True)
        thread.start()
        try:
            _follow(window, lambda: window.add_all(reader.take()), report, cancellation, plan, lambda: reader.error)
        finally:
            reader.stop = True
            thread.join(10.0)
        return StreamResult(window.columns(len(plan.channels)), window.trigger_index or 0, round(reader.lateness * 1e9))


class _Poller:
    """The poll loop on a thread of its own: a round of reads at each period instant."""

    def __init__(self, plan: StreamPlan, axes: Callable[[int], Drive]) -> None:
        self.plan = plan
        self.groups = [
            (axes(node), [n for n, ch in enumerate(plan.channels) if ch.node == node]) for node in plan.nodes
        ]
        self.samples: list[Sample] = []
        self.taken = 0
        self.lateness = 0.0
        self.error: str | None = None
        self.stop = False

    def take(self) -> list[Sample]:
        fresh = self.samples[self.taken :]
        self.taken += len(fresh)
        return fresh

    def run(self) -> None:
        period, start, k = self.plan.period_ns / 1e9, time.monotonic(), 0
        while not self.stop:
            delay = start + k * period - time.monotonic()
            if delay > 0:
                time.sleep(delay)
            try:
                self.samples.append(self._round(start + k * period))
            except ServoStudioError as error:
                self.error = str(error)
                return
            k += 1

    def _round(self, instant: float) -> Sample:
        values: list[int | float] = [0] * len(self.plan.channels)
        batches = [
            (positions, drive.submit_read_all([self.plan.channels[n].variable for n in positions]))
            for drive, positions in self.groups
        ]
        for positions, batch in batches:
            for position, outcome in zip(positions, batch.outcomes(), strict=True):
                if isinstance(outcome, Exception):
                    raise outcome
                raw = outcome.raw
                assert isinstance(raw, int | float)  # a recordable type
                values[position] = raw
        self.lateness = max(self.lateness, time.monotonic() - instant)
        return tuple(values)
