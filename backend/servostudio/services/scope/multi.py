"""Recorder captures of several axes of one bus (docs/scope.md §8): each drive's own recorder records its channels,
all of them started by one broadcast frame, and the recordings are joined into one capture.

Every recorder is configured by SDO (immediate trigger, single mode: the start is the common trigger), then armed
together: an RPDO of each drive (the highest-numbered one, borrowed and written back afterwards) is mapped with the
recorder's control object 0x5828 on one common identifier, applied on reception, and one frame carrying "arm"
reaches every drive at the same instant — each recorder takes its first record at the end of its next control
period, so the recordings start in the same control period. Every recorder's status is then read back: where a drive
could not take part (no RPDO, a mapping refused, the frame not taken), every recorder is stopped and armed again one
after the other by SDO, and the capture says so. ``alignment_ns`` states the largest offset two axes' samples can
have: one base period for the broadcast (drives whose control periods are not locked to each other; zero on the
simulator, whose drives share one tick), and for the sequential arm the measured time from the first arm request to
the last arm's confirmation plus one base period.
"""

from __future__ import annotations

import struct
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from datetime import UTC, datetime

from servostudio.drive.access import Drive
from servostudio.drive.link import BusLink
from servostudio.drive.nmt import NmtCommand, send_nmt
from servostudio.drive.rpdo import APPLY_ON_RECEPTION, RpdoConfig, last_rpdo, mapped, read_rpdo, write_rpdo
from servostudio.errors import ServoStudioError
from servostudio.services.cancel import Cancellation
from servostudio.services.scope.capture import FORMATS, Capture, ChannelInfo, DriveIdentity, decode_recording
from servostudio.services.scope.definition import CaptureDefinition, split_channel
from servostudio.services.scope.plan import CapturePlan, CaptureRefused, plan_capture, recorder_of
from servostudio.services.scope.recorder import RecorderSession, Report

#: how long the drives get to enter OPERATIONAL (NMT start) before the broadcast frame, and to act on it
NMT_SETTLE_S = 0.05
Axes = Callable[[int], Drive]


@dataclass(frozen=True)
class AxisPlan:
    """One drive's part of the capture: its recorder plan and where its channels sit in the capture."""

    drive: Drive
    plan: CapturePlan
    positions: tuple[int, ...]


@dataclass(frozen=True)
class MultiPlan:
    """A recorder capture of several axes, every part checked."""

    definition: CaptureDefinition
    node: int  # the capture's own node (channels without ``@``)
    axes: tuple[AxisPlan, ...]

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
    """How the recorders were started: ``broadcast`` or ``sequential`` (with the reason), and the alignment."""

    method: str
    alignment_ns: int
    note: str


def plan_multi(drive: Drive, axes: Axes, definition: CaptureDefinition) -> MultiPlan:
    """Each axis's recorder plan for its channels, one depth and one period for all; refused before anything is
    written when the start cannot be common (a trigger, a re-arm mode) or one axis cannot record its part."""
    if not definition.trigger.immediate or definition.mode != "single":
        raise CaptureRefused(
            "a recorder capture of several axes starts every recorder at one broadcast arm: immediate trigger and "
            "single mode only; a triggered capture of several axes uses source tpdo"
        )
    groups: dict[int, list[int]] = {}
    for position, channel in enumerate(definition.channels):
        groups.setdefault(split_channel(channel)[1] or drive.node, []).append(position)
    parts = [_axis(drive if node == drive.node else axes(node), definition, positions) for node, positions in
             groups.items()]  # fmt: skip
    depth = min(part.plan.depth for part in parts)
    if definition.samples is None and any(part.plan.depth != depth for part in parts):
        parts = [_axis(part.drive, replace(definition, samples=depth), part.positions) for part in parts]
    if len({part.plan.period_ns for part in parts}) > 1:
        raise CaptureRefused("the axes' recorders have different base periods: no common sample period")
    return MultiPlan(definition, drive.node, tuple(parts))


def _axis(drive: Drive, definition: CaptureDefinition, positions: Sequence[int]) -> AxisPlan:
    own = replace(definition, channels=tuple(split_channel(definition.channels[n])[0] for n in positions))
    session = RecorderSession(drive, recorder_of(drive))
    return AxisPlan(drive, plan_capture(drive, session.recorder, session.limits(), own), tuple(positions))


class MultiRecorderCapture:
    """One run of a `MultiPlan`: configure, arm together, wait, upload, join."""

    def __init__(self, plan: MultiPlan, link: BusLink, operational: Callable[[int], bool]) -> None:
        self.plan, self.link, self.operational = plan, link, operational
        self.sessions = [RecorderSession(axis.drive, recorder_of(axis.drive)) for axis in plan.axes]
        self.armed: Armed | None = None

    def run(self, report: Report, cancellation: Cancellation, identity: DriveIdentity) -> Capture:
        for session, axis in zip(self.sessions, self.plan.axes, strict=True):
            session.configure(axis.plan)
        counters = [session.read("counter") for session in self.sessions]
        self.armed = self._arm()
        report({"stage": "armed", "arm": self.armed.method, "alignment_ns": self.armed.alignment_ns,
                "note": self.armed.note})  # fmt: skip
        for session, axis, counter in zip(self.sessions, self.plan.axes, counters, strict=True):
            session.wait_recording(axis.plan, report, cancellation, counter)
        recordings = [session.upload(axis.plan, report, cancellation)
                      for session, axis in zip(self.sessions, self.plan.axes, strict=True)]  # fmt: skip
        columns = [decode_recording(axis.plan, rec.data) for axis, rec in zip(self.plan.axes, recordings, strict=True)]
        return self._joined(columns, identity)

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
    def _joined(self, parts: list[tuple[tuple[int | float, ...], ...]], identity: DriveIdentity) -> Capture:
        plan = self.plan
        channels: list[ChannelInfo | None] = [None] * len(plan.definition.channels)
        columns: list[tuple[int | float, ...]] = [()] * len(channels)
        for axis, part in zip(plan.axes, parts, strict=True):
            for position, channel, column in zip(axis.positions, axis.plan.channels, part, strict=True):
                info = ChannelInfo.of(channel.variable)
                suffix = "" if axis.drive.node == plan.node else f"@{axis.drive.node}"
                channels[position] = replace(info, key=info.key + suffix)
                columns[position] = column
        assert self.armed is not None
        return Capture(
            definition=plan.definition,
            channels=tuple(info for info in channels if info is not None),
            period_ns=plan.period_ns,
            trigger_index=0,
            trigger="immediate",
            columns=tuple(columns),
            drive=identity,
            captured_at=_now(),
            alignment_ns=self.armed.alignment_ns,
        )


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
