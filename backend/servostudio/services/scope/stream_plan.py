"""Captures without the drive's recorder, planned: synchronous TPDOs at the server's SYNC, or SDO polling as the last
resort (docs/scope.md §7). Channels may come from several axes of one bus (``0x6064,0@2``).

The plan says before anything is written what the capture will be: its source, the TPDOs it borrows on each
node, its rate, the frames per second it puts on the bus and the bus load they make, and how well the axes are
aligned. Every refusal names its reason: a period below the SYNC producer's 1 ms or one the bus cannot carry, a
trigger that is not one of the channels, more samples than the server keeps, a poll faster than the drives answer.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass

from servostudio.drive.access import Drive
from servostudio.drive.sync import MIN_PERIOD_S
from servostudio.drive.tpdo import PDO_BYTES, TpdoSlot, tpdo_slots
from servostudio.od.model import Variable
from servostudio.services.scope.definition import DEFAULT_SAMPLES, CaptureDefinition, number_text, split_channel
from servostudio.services.scope.plan import CaptureRefused, object_key, pre_trigger_samples, raw_level, recordable

#: the samples a stream capture keeps (4 channels of 32 bits: 3 MB)
MAX_SAMPLES = 200_000
#: the share of the bus a capture may take: the rest is for SDO, heartbeats, EMCY and the machine's own PDOs
MAX_BUS_LOAD = 0.7
#: the bit rate assumed where the spec does not give it (socketcan, socketcand, virtual and simulated buses)
ASSUMED_BITRATE = 1_000_000
#: a polled sample may take this share of its period at most (the rest absorbs the host's scheduling)
POLL_MARGIN = 1.5
#: rounds of reads a poll plan times (the best counts: one slow round is the host, not the drive)
TIMED_ROUNDS = 3
Axes = Callable[[int], Drive]


def frame_bits(data_bytes: int) -> int:
    """A standard CAN frame's bits with the worst-case stuff bits and the interframe space."""
    return 47 + 8 * data_bytes + (34 + 8 * data_bytes - 1) // 4


@dataclass(frozen=True)
class StreamChannel:
    node: int
    variable: Variable
    key: str  # as captures spell it: 0x606C,0 on the capture's node, 0x606C,0@2 on another axis

    @property
    def size(self) -> int:
        return self.variable.data_type.fixed_size


@dataclass(frozen=True)
class TpdoUse:
    """One borrowed TPDO: the node, the slot, the plan's channels it carries (positions, in mapping order)."""

    node: int
    slot: TpdoSlot
    channels: tuple[int, ...]


@dataclass(frozen=True)
class Bus:
    """What the plan knows of the bus: its bit rate (or the one assumed)."""

    bitrate: int | None

    @property
    def rate(self) -> int:
        return self.bitrate or ASSUMED_BITRATE


@dataclass(frozen=True)
class StreamPlan:
    definition: CaptureDefinition
    source: str  # tpdo | poll
    node: int  # the capture's own node
    channels: tuple[StreamChannel, ...]
    tpdos: tuple[TpdoUse, ...]
    period_ns: int
    depth: int
    pre_trigger: int
    trigger_channel: int | None  # position in channels; None: immediate
    trigger_level: int
    trigger_edge: str
    frames_per_s: float
    bus_load: float
    bitrate: int
    bitrate_known: bool
    min_period_ns: int

    @property
    def nodes(self) -> tuple[int, ...]:
        return tuple(dict.fromkeys(channel.node for channel in self.channels))

    @property
    def rate_hz(self) -> float:
        return 1e9 / self.period_ns

    @property
    def trigger_variable(self) -> Variable | None:
        return None if self.trigger_channel is None else self.channels[self.trigger_channel].variable

    def alignment(self) -> str:
        """How the samples of the channels (and axes) line up, as the plan can say before the capture."""
        if self.source == "tpdo":
            return (
                "every drive samples at the same SYNC frame: the axes are aligned to the sample; each sample is "
                "the drive's value at its SYNC (a signal the drive updates more slowly shows its own steps)"
            )
        return (
            f"polled by SDO: a sample's values are read one after the other within its {self.period_ns / 1e6:g} ms "
            "period, the axes in parallel; the capture states the largest distance of a read from its instant"
        )

    def describe(self) -> dict[str, object]:
        """The preview the page, the REST API and the CLI show before arming."""
        return {
            "source": self.source,
            "rate_hz": self.rate_hz,
            "period_ns": self.period_ns,
            "min_period_ns": self.min_period_ns,
            "samples": self.depth,
            "pre_trigger": self.pre_trigger,
            "frames_per_s": round(self.frames_per_s, 1),
            "bus_load": round(self.bus_load, 4),
            "bitrate": self.bitrate,
            "bitrate_assumed": not self.bitrate_known,
            "nodes": list(self.nodes),
            "tpdos": [
                {"node": use.node, "tpdo": use.slot.number + 1, "channels": len(use.channels)} for use in self.tpdos
            ],
            "alignment": self.alignment(),
        }


def stream_channels(drive: Drive, axes: Axes, definition: CaptureDefinition) -> tuple[StreamChannel, ...]:
    """The channels with their nodes; each must be recordable (the TPDO rule; polling reads the same objects)."""
    channels = []
    for text in definition.channels:
        name, node = split_channel(text)
        owner = drive if node in (None, drive.node) else axes(node or drive.node)
        variable = recordable(owner, name, "channel")
        key = object_key(variable) if owner.node == drive.node else f"{object_key(variable)}@{owner.node}"
        channels.append(StreamChannel(owner.node, variable, key))
    return tuple(channels)


def plan_stream(drive: Drive, axes: Axes, definition: CaptureDefinition, bus: Bus, source: str = "auto") -> StreamPlan:
    """The TPDO plan when every node's channels fit its TPDOs (``source`` tpdo or auto), else the poll plan."""
    if not drive.profile.canopen:
        raise CaptureRefused(
            f"node {drive.node} is a {drive.profile.fieldbus} drive ({drive.profile.device}): the scope's captures "
            "and roll mode need a CANopen drive (TPDOs at the SYNC, a recorder, or PDO-mappable objects to poll)"
        )
    if definition.mode != "single":
        raise CaptureRefused(f"mode {definition.mode}: normal and auto re-arm need the drive's recorder")
    channels = stream_channels(drive, axes, definition)
    owners = {channel.node: (drive if channel.node == drive.node else axes(channel.node)) for channel in channels}
    tpdos = None if source == "poll" else _assign(channels, owners)
    if tpdos is None and source == "tpdo":
        raise CaptureRefused(_no_fit(channels, owners))
    period_ns = _period_ns(definition.period_us)
    depth = _depth(definition, period_ns)
    trigger_channel, level, edge = _trigger(drive.node, channels, definition)
    base = _Base(definition, drive.node, channels, period_ns, depth, trigger_channel, level, edge, bus)
    return _tpdo_plan(base, tpdos) if tpdos is not None else _poll_plan(base, owners)


@dataclass(frozen=True)
class _Base:
    """What the TPDO and the poll plans share."""

    definition: CaptureDefinition
    node: int
    channels: tuple[StreamChannel, ...]
    period_ns: int
    depth: int
    trigger_channel: int | None
    trigger_level: int
    trigger_edge: str
    bus: Bus

    def plan(
        self, source: str, tpdos: tuple[TpdoUse, ...], frames_per_s: float, load: float, fastest: int
    ) -> StreamPlan:
        return StreamPlan(
            definition=self.definition,
            source=source,
            node=self.node,
            channels=self.channels,
            tpdos=tpdos,
            period_ns=self.period_ns,
            depth=self.depth,
            pre_trigger=pre_trigger_samples(self.definition, self.depth),
            trigger_channel=self.trigger_channel,
            trigger_level=self.trigger_level,
            trigger_edge=self.trigger_edge,
            frames_per_s=frames_per_s,
            bus_load=load,
            bitrate=self.bus.rate,
            bitrate_known=self.bus.bitrate is not None,
            min_period_ns=fastest,
        )


def _assign(channels: tuple[StreamChannel, ...], owners: dict[int, Drive]) -> tuple[TpdoUse, ...] | None:
    """Each node's channels packed in order into its TPDOs, the highest-numbered first (TPDO 1 often carries the
    status word a master watches); None when some node's channels do not fit."""
    uses: list[TpdoUse] = []
    for node, owner in owners.items():
        positions = [n for n, channel in enumerate(channels) if channel.node == node]
        slots = sorted(tpdo_slots(owner.dictionary), key=lambda slot: -slot.number) if owner.dictionary else []
        packed = _pack(channels, positions, slots)
        if packed is None:
            return None
        uses += [TpdoUse(node, slot, tuple(group)) for slot, group in packed]
    return tuple(uses)


def _pack(
    channels: tuple[StreamChannel, ...], positions: list[int], slots: list[TpdoSlot]
) -> list[tuple[TpdoSlot, list[int]]] | None:
    packed: list[tuple[TpdoSlot, list[int]]] = []
    for position in positions:
        size = channels[position].size
        if packed:
            slot, group = packed[-1]
            if len(group) < slot.entries and sum(channels[n].size for n in group) + size <= PDO_BYTES:
                group.append(position)
                continue
        if len(packed) == len(slots):
            return None
        packed.append((slots[len(packed)], [position]))
    return packed


def _no_fit(channels: tuple[StreamChannel, ...], owners: dict[int, Drive]) -> str:
    counts = {node: len(tpdo_slots(owner.dictionary)) if owner.dictionary else 0 for node, owner in owners.items()}
    shown = ", ".join(f"node {node}: {count} TPDOs of 8 bytes" for node, count in counts.items())
    return f"the {len(channels)} channels do not fit the TPDOs the drives offer ({shown}); use fewer or poll"


def _period_ns(period_us: float) -> int:
    period_ns = round(period_us * 1000)
    if period_ns < MIN_PERIOD_S * 1e9 or abs(period_us * 1000 - period_ns) > 1e-6:
        raise CaptureRefused(
            f"period {number_text(period_us)} µs: without the drive's recorder the server's SYNC producer sets the "
            f"rate, every {MIN_PERIOD_S * 1e6:.0f} µs at the fastest (whole µs)"
        )
    return period_ns


def _depth(definition: CaptureDefinition, period_ns: int) -> int:
    if definition.samples is not None:
        depth = definition.samples
    elif definition.duration_s is not None:
        depth = math.ceil(round(definition.duration_s * 1e9 / period_ns, 6))
    else:
        depth = DEFAULT_SAMPLES
    if not 2 <= depth <= MAX_SAMPLES:
        raise CaptureRefused(f"{depth} samples: a capture without the recorder takes 2..{MAX_SAMPLES}")
    return depth


def _trigger(
    own: int, channels: tuple[StreamChannel, ...], definition: CaptureDefinition
) -> tuple[int | None, int, str]:
    """(the trigger channel's position, raw level, edge): the server sees only the channels it receives."""
    trigger = definition.trigger
    if trigger.source is None:
        return None, 0, trigger.edge
    name, node = split_channel(trigger.source)
    for position, channel in enumerate(channels):
        if channel.node == (node or own) and _names(channel, name):
            return position, raw_level(channel.variable, trigger.edge, trigger.level), trigger.edge
    raise CaptureRefused(
        f"trigger source {trigger.source!r}: without the drive's recorder the trigger must be one of the channels"
    )


def _names(channel: StreamChannel, name: str) -> bool:
    """Does ``name`` (an address or the dictionary name) name this channel's object?"""
    variable = channel.variable
    return name in (object_key(variable), variable.name, f"0x{variable.index:04X}") or _same_address(name, variable)


def _same_address(name: str, variable: Variable) -> bool:
    text = name.strip().lower().replace("sub", ",")
    index, _, sub = text.partition(",")
    try:
        return int(index, 16) == variable.index and int(sub or "0", 0) == variable.subindex
    except ValueError:
        return False


def _tpdo_plan(base: _Base, tpdos: tuple[TpdoUse, ...]) -> StreamPlan:
    channels, rate = base.channels, base.bus.rate
    bits = frame_bits(0) + sum(frame_bits(sum(channels[n].size for n in use.channels)) for use in tpdos)
    fastest = max(round(MIN_PERIOD_S * 1e9), math.ceil(bits / (MAX_BUS_LOAD * rate) * 1e6) * 1000)
    load = bits * 1e9 / base.period_ns / rate
    if base.period_ns < fastest:
        raise CaptureRefused(
            f"period {base.period_ns / 1000:g} µs: {len(tpdos)} TPDOs and the SYNC take {bits} bits per sample, "
            f"{load:.0%} of {rate / 1e6:g} Mbit/s; the bus allows {fastest / 1000:g} µs at the fastest "
            f"(at most {MAX_BUS_LOAD:.0%} load)"
        )
    return base.plan("tpdo", tpdos, (len(tpdos) + 1) * 1e9 / base.period_ns, load, fastest)


def _poll_plan(base: _Base, owners: dict[int, Drive]) -> StreamPlan:
    """Polling: the period must leave room for the reads the drives need (measured now: one round of reads)."""
    channels = base.channels
    round_trip = max(
        _read_time(owner, [channel.variable for channel in channels if channel.node == node])
        for node, owner in owners.items()
    )
    fastest = max(round(MIN_PERIOD_S * 1e9), math.ceil(round_trip * POLL_MARGIN * 1e3) * 1_000_000)
    frames = 2 * len(channels) * 1e9 / base.period_ns
    if base.period_ns < fastest:
        raise CaptureRefused(
            f"period {base.period_ns / 1000:g} µs: polling {len(channels)} channels by SDO takes "
            f"{round_trip * 1e3:.1f} ms per sample here; the fastest poll is every {fastest / 1e6:g} ms"
        )
    return base.plan("poll", (), frames, frames * frame_bits(8) / base.bus.rate, fastest)


def _read_time(drive: Drive, variables: list[Variable]) -> float:
    """Seconds a round of reads of ``variables`` takes, the best of ``TIMED_ROUNDS`` (reads change nothing; a
    failure is the refusal)."""
    return min(_round_time(drive, variables) for _ in range(TIMED_ROUNDS))


def _round_time(drive: Drive, variables: list[Variable]) -> float:
    started = time.monotonic()
    for outcome in drive.submit_read_all(variables).outcomes():
        if isinstance(outcome, Exception):
            raise outcome
    return time.monotonic() - started
