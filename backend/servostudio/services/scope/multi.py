"""Recorder captures of several axes of one bus (docs/scope.md §7): each drive's own recorder records its channels,
all of them started together, and the recordings are joined into one capture.

Without a trigger every recorder is configured by SDO (immediate, single mode: the start is the common trigger) and
armed together: an RPDO of each drive (the highest-numbered one, borrowed and written back afterwards) is mapped with
the recorder's control object 0x5828 on one common identifier, applied on reception, and one frame carrying "arm"
reaches every drive at the same instant — each recorder takes its first record at the end of its next control
period, so the recordings start in the same control period. Every recorder's status is then read back: where a drive
could not take part (no RPDO, a mapping refused, the frame not taken), every recorder is stopped and armed again one
after the other by SDO, and the capture says so. ``alignment_ns`` states the largest offset two axes' samples can
have: one base period for the broadcast (drives whose control periods are not locked to each other; zero on the
simulator, whose drives share one tick), and for the sequential arm the measured time from the first arm request to
the last arm's confirmation plus one base period.

With a trigger on one axis the start is that axis's trigger instead: the other recorders trigger on the trigger
drive's recorder status, which its TPDO carries to their RPDOs (``relay.py``), one control period later and with a
pre-trigger one sample longer, so all recordings cover the same control periods; ``alignment_ns`` is then the larger
of one base period and the relayed frame's time on the bus.
"""

from __future__ import annotations

import contextlib
import struct
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from datetime import UTC, datetime

from servostudio.drive.access import Drive
from servostudio.drive.link import BusLink
from servostudio.drive.nmt import NmtCommand, send_nmt
from servostudio.drive.rpdo import APPLY_ON_RECEPTION, RpdoConfig, last_rpdo, mapped, read_rpdo, write_rpdo
from servostudio.errors import CommunicationError, ServoStudioError
from servostudio.services.cancel import Cancellation, Cancelled
from servostudio.services.scope.capture import FORMATS, Capture, ChannelInfo, DriveIdentity, decode_recording
from servostudio.services.scope.definition import CaptureDefinition, Trigger, split_channel
from servostudio.services.scope.plan import (
    CapturePlan,
    CaptureRefused,
    PlannedChannel,
    object_key,
    plan_capture,
    recorder_of,
)
from servostudio.services.scope.recorder import NoTrigger, RecorderSession, Recording, Report
from servostudio.services.scope.relay import RELAY_DELAY, TriggerRelay, relay_object, relay_slot
from servostudio.services.scope.stream_plan import ASSUMED_BITRATE, frame_bits

#: how long the drives get to enter OPERATIONAL (NMT start) before the broadcast frame, and to act on it
NMT_SETTLE_S = 0.05
#: how long the followers of a triggered capture get, after the trigger drive's recording completed, to complete
#: theirs (one control period later; seconds of wall clock for a loaded host)
FOLLOW_S = 5.0
Axes = Callable[[int], Drive]


class RelayLeft(CommunicationError):
    """A triggered capture of several axes failed and some borrowed PDO could not be written back (named)."""


@dataclass(frozen=True)
class AxisPlan:
    """One drive's part of the capture: its recorder plan and where its channels sit in the capture."""

    drive: Drive
    plan: CapturePlan
    positions: tuple[int, ...]
    #: records this axis's trigger record lags the trigger instant (a follower of the trigger drive's relay: 1)
    delay: int = 0


@dataclass(frozen=True)
class MultiPlan:
    """A recorder capture of several axes, every part checked."""

    definition: CaptureDefinition
    node: int  # the capture's own node (channels without ``@``)
    axes: tuple[AxisPlan, ...]
    trigger_node: int | None = None  # the node whose object triggers (None: immediate, the arm is the start)

    @property
    def triggered(self) -> bool:
        return self.trigger_node is not None

    @property
    def nodes(self) -> tuple[int, ...]:
        return tuple(axis.drive.node for axis in self.axes)

    @property
    def period_ns(self) -> int:
        return self.axes[0].plan.period_ns

    @property
    def depth(self) -> int:
        return self.axes[0].plan.depth


@dataclass(frozen=True)
class Armed:
    """How the recorders were started: ``broadcast``, ``sequential`` (with the reason) or ``relay`` (triggered: the
    others followed the trigger drive), and the alignment."""

    method: str
    alignment_ns: int
    note: str


def plan_multi(drive: Drive, axes: Axes, definition: CaptureDefinition) -> MultiPlan:
    """Each axis's recorder plan for its channels, one depth and one period for all; refused before anything is
    written when the start cannot be common (a re-arm mode, a trigger the other drives cannot follow) or one axis
    cannot record its part."""
    if definition.mode != "single":
        raise CaptureRefused(
            "a recorder capture of several axes is single mode only: in normal and auto mode each recorder re-arms "
            "by itself after its own recording, so the axes' next recordings would not start together"
        )
    groups: dict[int, list[int]] = {}
    for position, channel in enumerate(definition.channels):
        groups.setdefault(split_channel(channel)[1] or drive.node, []).append(position)
    trigger_node = None if definition.trigger.immediate else _trigger_node(drive, definition, groups)
    reach = {node: drive if node == drive.node else axes(node) for node in groups}
    parts = _parts(reach, definition, groups, trigger_node)
    depth = min(part.plan.depth for part in parts)
    if definition.samples is None and any(part.plan.depth != depth for part in parts):
        parts = _parts(reach, replace(definition, samples=depth), groups, trigger_node)
    if len({part.plan.period_ns for part in parts}) > 1:
        raise CaptureRefused("the axes' recorders have different base periods: no common sample period")
    return MultiPlan(definition, drive.node, tuple(parts), trigger_node)


def _trigger_node(drive: Drive, definition: CaptureDefinition, groups: dict[int, list[int]]) -> int:
    """The axis whose object triggers (``OBJ@NODE``, else the capture's node); it must be one of the capture's."""
    source = definition.trigger.source
    assert source is not None
    node = split_channel(source)[1] or drive.node
    if node not in groups:
        raise CaptureRefused(f"trigger source {source!r}: node {node} has no channel in this capture")
    return node


def _parts(reach: dict[int, Drive], definition: CaptureDefinition, groups: dict[int, list[int]],
           trigger_node: int | None) -> list[AxisPlan]:  # fmt: skip
    """Each axis's plan: the trigger axis's with the trigger, the followers' on the relay (after it)."""
    if trigger_node is None:
        return [_axis(reach[node], definition, positions) for node, positions in groups.items()]
    lead = _axis(reach[trigger_node], definition, groups[trigger_node])
    relay_slot(lead.drive)
    follow = replace(definition, trigger=Trigger(), pre_trigger_pct=0.0)
    followers = [_follower(_axis(reach[node], follow, positions), lead.plan) for node, positions in groups.items()
                 if node != trigger_node]  # fmt: skip
    return [lead, *followers]


def _axis(drive: Drive, definition: CaptureDefinition, positions: Sequence[int]) -> AxisPlan:
    own = replace(definition, channels=tuple(split_channel(definition.channels[n])[0] for n in positions))
    if own.trigger.source is not None:
        own = replace(own, trigger=replace(own.trigger, source=split_channel(own.trigger.source)[0]))
    session = RecorderSession(drive, recorder_of(drive))
    return AxisPlan(drive, plan_capture(drive, session.recorder, session.limits(), own), tuple(positions))


def _follower(part: AxisPlan, lead: CapturePlan) -> AxisPlan:
    """An axis that triggers on the relay rising through the "recording" status code, one record after the
    trigger drive: its pre-trigger one sample longer, so its recording covers the same control periods."""
    drive, recorder = part.drive, recorder_of(part.drive)
    pre_trigger = lead.pre_trigger + RELAY_DELAY
    if pre_trigger > part.plan.depth - 1:
        raise CaptureRefused(
            f"pre-trigger {lead.pre_trigger} of {lead.depth} samples: node {drive.node} follows the trigger one "
            "sample later and needs one sample more before it; use a smaller pre-trigger"
        )
    relay = drive.variable(relay_object(drive))
    plan = replace(
        part.plan,
        trigger_mode=recorder.trigger_modes["edge"],
        trigger_source=PlannedChannel(relay).pointer,
        trigger_variable=relay,
        trigger_level=recorder.statuses.index("recording"),
        trigger_edge=recorder.edges["rising"],
        pre_trigger=pre_trigger,
    )
    return replace(part, plan=plan, delay=RELAY_DELAY)


class MultiRecorderCapture:
    """One run of a `MultiPlan`: configure, arm together (or on the trigger drive's relay), wait, upload, join."""

    def __init__(self, plan: MultiPlan, link: BusLink, operational: Callable[[int], bool],
                 bitrate: int | None = None) -> None:  # fmt: skip
        self.plan, self.link, self.operational, self.bitrate = plan, link, operational, bitrate
        self.sessions = [RecorderSession(axis.drive, recorder_of(axis.drive)) for axis in plan.axes]
        self.armed: Armed | None = None

    def run(self, report: Report, cancellation: Cancellation, identity: DriveIdentity) -> Capture:
        for session, axis in zip(self.sessions, self.plan.axes, strict=True):
            session.configure(axis.plan)
        counters = [session.read("counter") for session in self.sessions]
        try:
            if self.plan.triggered:
                self._relayed(report, cancellation, counters)
            else:
                self._broadcast(report, cancellation, counters)
        except (ServoStudioError, Cancelled):
            self._stop_all()  # no recorder is left armed after a failure or a cancel
            raise
        recordings = [session.upload(axis.plan, report, cancellation)
                      for session, axis in zip(self.sessions, self.plan.axes, strict=True)]  # fmt: skip
        return self._joined(recordings, identity)

    def _broadcast(self, report: Report, cancellation: Cancellation, counters: list[int]) -> None:
        self.armed = self._arm()
        self._report_armed(report)
        for session, axis, counter in zip(self.sessions, self.plan.axes, counters, strict=True):
            session.wait_recording(axis.plan, report, cancellation, counter)

    def _report_armed(self, report: Report) -> None:
        assert self.armed is not None
        report({"stage": "armed", "arm": self.armed.method, "alignment_ns": self.armed.alignment_ns,
                "note": self.armed.note})  # fmt: skip

    def _stop_all(self) -> None:
        for session in self.sessions:
            with contextlib.suppress(ServoStudioError):  # a drive gone: the error that ended the capture says why
                session.command("stop")

    # -- the trigger drive's relay ----------------------------------------------------------------------------------
    def _relayed(self, report: Report, cancellation: Cancellation, counters: list[int]) -> None:
        """The followers armed first (so they are waiting before the trigger can fire), then the trigger drive; the
        relay written back as soon as every recording is complete (also after a failure)."""
        lead, *followers = [axis.drive for axis in self.plan.axes]
        relay = TriggerRelay(lead, followers, self.link, self.operational)
        try:
            relay.open()
            for session in [*self.sessions[1:], self.sessions[0]]:
                session.command("arm")
            self.armed = self._relay_armed()
            self._report_armed(report)
            self._wait_relayed(report, cancellation, counters)
        except (ServoStudioError, Cancelled) as error:
            left = relay.restore()
            if left:
                raise RelayLeft(f"{error}{left}") from error
            raise
        self.armed = replace(self.armed, note=self.armed.note + relay.restore())

    def _relay_armed(self) -> Armed:
        """The followers' samples are within one base period of the trigger drive's when its status frame reaches
        them within one period (their unlocked control periods are the rest); a slower frame widens it."""
        lead = self.plan.axes[0]
        frame_ns = round(frame_bits(1) * 1e9 / (self.bitrate or ASSUMED_BITRATE))
        alignment = max(lead.plan.base_period_ns, frame_ns)
        others = ", ".join(str(axis.drive.node) for axis in self.plan.axes[1:])
        return Armed("relay", alignment, f"node {lead.drive.node}'s recorder triggered and sent its status in a "
                     f"TPDO; the recorders of node {others} triggered on it one control period later "
                     "(pre-trigger one sample longer): the recordings cover the same control periods")  # fmt: skip

    def _wait_relayed(self, report: Report, cancellation: Cancellation, counters: list[int]) -> None:
        """The trigger drive's recording (the user's timeout), then the followers', which end one period later."""
        lead = self.plan.axes[0]
        self.sessions[0].wait_recording(lead.plan, report, cancellation, counters[0])
        for session, axis, counter in zip(self.sessions[1:], self.plan.axes[1:], counters[1:], strict=True):
            bounded = replace(axis.plan, definition=replace(axis.plan.definition, timeout_s=FOLLOW_S))
            try:
                session.wait_recording(bounded, report, cancellation, counter)
            except NoTrigger:
                raise NoTrigger(
                    f"node {axis.drive.node}: its recorder did not follow node {lead.drive.node}'s trigger within "
                    f"{FOLLOW_S:g} s (the relayed status frame did not reach it, or the trigger was forced during "
                    "its pre-trigger); the recorders were stopped"
                ) from None

    # -- arming --------------------------------------------------------------------------------------------------
    def _arm(self) -> Armed:
        """The broadcast arm, or the sequential one where a drive cannot take part (every recorder stopped first)."""
        broadcast = BroadcastArm(self.plan, self.link, self.operational)
        try:
            missing = broadcast.run()
        except ServoStudioError as error:
            missing = f"the broadcast arm could not be set up ({error})"
        finally:
            left = broadcast.restore()
        if missing is None:
            base = self.plan.axes[0].plan.base_period_ns
            return Armed("broadcast", base, "one broadcast frame armed every recorder in the same control period"
                         + left)  # fmt: skip
        for session in self.sessions:
            session.command("stop")
        armed = self._sequential(missing)
        return replace(armed, note=armed.note + left)

    def _sequential(self, reason: str) -> Armed:
        started = time.monotonic()
        for session in self.sessions:
            session.command("arm")
        span_ns = round((time.monotonic() - started) * 1e9)
        base = self.plan.axes[0].plan.base_period_ns
        return Armed("sequential", span_ns + base, f"{reason}; the recorders were armed one after the other by SDO")

    # -- the capture ---------------------------------------------------------------------------------------------
    def _joined(self, recordings: list[Recording], identity: DriveIdentity) -> Capture:
        """Every axis's columns cut to the control periods all recordings cover, the trigger sample lined up (a
        follower's trigger record is its relay delay after the trigger instant)."""
        plan = self.plan
        at = [rec.trigger_record - axis.delay for axis, rec in zip(plan.axes, recordings, strict=True)]
        before = min(at)
        after = min(rec.records - first for rec, first in zip(recordings, at, strict=True))
        channels: list[ChannelInfo | None] = [None] * len(plan.definition.channels)
        columns: list[tuple[int | float, ...]] = [()] * len(channels)
        for axis, rec, first in zip(plan.axes, recordings, at, strict=True):
            part = decode_recording(axis.plan, rec.data)
            for position, channel, column in zip(axis.positions, axis.plan.channels, part, strict=True):
                info = ChannelInfo.of(channel.variable)
                channels[position] = replace(info, key=info.key + self._suffix(axis))
                columns[position] = column[first - before : first + after]
        assert self.armed is not None
        return Capture(
            definition=plan.definition,
            channels=tuple(info for info in channels if info is not None),
            period_ns=plan.period_ns,
            trigger_index=before,
            trigger=self._trigger_text(),
            columns=tuple(columns),
            drive=identity,
            captured_at=_now(),
            alignment_ns=self.armed.alignment_ns,
        )

    def _suffix(self, axis: AxisPlan) -> str:
        return "" if axis.drive.node == self.plan.node else f"@{axis.drive.node}"

    def _trigger_text(self) -> str:
        """The trigger as captures show it (the source with its node when it is another axis's)."""
        trigger, lead = self.plan.definition.trigger, self.plan.axes[0]
        variable = lead.plan.trigger_variable
        if not self.plan.triggered or variable is None:
            return "immediate"
        source = object_key(variable) + self._suffix(lead)
        return Trigger(source, trigger.edge, trigger.level).describe(variable.unit)


class BroadcastArm:
    """The borrowed RPDOs that carry one "arm" frame to every recorder, and putting them back."""

    def __init__(self, plan: MultiPlan, link: BusLink, operational: Callable[[int], bool]) -> None:
        self.plan, self.link, self.operational = plan, link, operational
        self.saved: list[tuple[Drive, RpdoConfig]] = []
        self.started: list[int] = []

    def run(self) -> str | None:
        """Arm every recorder with one frame; None when all took it, else why not. ``restore`` follows in any case."""
        identifier, frame = self._map()
        for node in self.started:
            send_nmt(self.link, NmtCommand.START, node)
        time.sleep(NMT_SETTLE_S if self.started else 0)
        self.link.send(identifier, frame)
        time.sleep(NMT_SETTLE_S)
        return self._missing()

    def _map(self) -> tuple[int, bytes]:
        """Each drive's last RPDO saved, then mapped with the control object on the first one's identifier."""
        drives = [axis.drive for axis in self.plan.axes]
        for drive in drives:
            self.saved.append((drive, read_rpdo(drive, last_rpdo(drive))))
        identifier = self.saved[0][1].identifier
        for drive, saved in self.saved:
            control = drive.variable(recorder_of(drive).address("control"))
            if not control.pdo_mappable:
                raise CaptureRefused(f"node {drive.node}: {control.label} cannot be mapped in an RPDO")
            write_rpdo(drive, mapped(saved.number, identifier, [control], APPLY_ON_RECEPTION))
        self.started = [drive.node for drive in drives if not self.operational(drive.node)]
        first = drives[0]
        control = first.variable(recorder_of(first).address("control"))
        arm = recorder_of(first).commands["arm"]
        return identifier, struct.pack("<" + FORMATS[control.data_type], arm)

    def _missing(self) -> str | None:
        idle = [axis.drive.node for axis in self.plan.axes if _idle(axis.drive)]
        return f"node {', '.join(map(str, idle))} did not take the broadcast arm" if idle else None

    def restore(self) -> str:
        """Every borrowed RPDO back as it was, the started nodes back to PRE-OPERATIONAL (each tried); what could not
        be done, as the end of the capture's note ("" when all was)."""
        failures: list[str] = []
        for drive, saved in self.saved:
            try:
                write_rpdo(drive, saved)
            except ServoStudioError as error:
                failures.append(
                    f"node {drive.node} RPDO {saved.number + 1} left mapped with the recorder's control: {error}"
                )
        for node in self.started:
            try:
                send_nmt(self.link, NmtCommand.PRE_OPERATIONAL, node)
            except ServoStudioError as error:
                failures.append(f"node {node} left OPERATIONAL: {error}")
        return "".join(f"; {failure}" for failure in failures)


def _idle(drive: Drive) -> bool:
    session = RecorderSession(drive, recorder_of(drive))
    return session.status() == "idle"


def _now() -> str:
    return datetime.now(UTC).isoformat(timespec="seconds").replace("+00:00", "Z")
