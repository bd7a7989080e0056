"""A capture definition checked against one drive and turned into the recorder's raw settings.

Every refusal the recorder would give at arm, and every mistake it would not catch (a trigger level the source can
never cross), is found here, before anything is written, and names its reason: an unknown object, one a TPDO could
not carry, a depth beyond the buffer for these channel sizes, a period that is no multiple of the base period.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from servostudio.drive.access import Drive, UnknownObjectError
from servostudio.drive.profiles.recorder import RecorderDescription
from servostudio.errors import InvalidInput
from servostudio.od.datatypes import DataType
from servostudio.od.model import Variable
from servostudio.od.pointer import Pointer
from servostudio.services.scope.definition import (
    DEFAULT_SAMPLES,
    CaptureDefinition,
    fixed_point_text,
    number_text,
    split_channel,
)

#: what a channel or a trigger source can be: the numbers a TPDO can carry (docs/eds.md §6)
RECORDABLE_TYPES = frozenset(
    {
        DataType.INTEGER8,
        DataType.INTEGER16,
        DataType.INTEGER32,
        DataType.UNSIGNED8,
        DataType.UNSIGNED16,
        DataType.UNSIGNED32,
        DataType.REAL32,
    }
)
#: the recorder compares with its level as a signed 32-bit raw value (0x5822,1)
LEVEL_RANGE = (-(2**31), 2**31 - 1)


class CaptureRefused(InvalidInput):
    """The drive cannot make this capture; nothing was written to it."""


class NoRecorder(CaptureRefused):
    """The drive has no in-drive recorder."""


@dataclass(frozen=True)
class RecorderLimits:
    """What the drive's recorder can do, as it reports itself (read-only objects: reading them changes nothing)."""

    capacity: int  # bytes of one recording
    base_period_ns: int


def object_key(variable: Variable) -> str:
    """How captures spell an object everywhere (CSV header, sidecar, page): ``0x606C,0``."""
    return f"0x{variable.index:04X},{variable.subindex}"


@dataclass(frozen=True)
class PlannedChannel:
    variable: Variable

    @property
    def key(self) -> str:
        return object_key(self.variable)

    @property
    def size(self) -> int:
        return self.variable.data_type.fixed_size

    @property
    def pointer(self) -> int:
        """The recorder's source pointer: index << 16 | sub << 8 | size in bits."""
        return Pointer(self.variable.index, self.variable.subindex, self.size * 8).encode()


@dataclass(frozen=True)
class CapturePlan:
    """The raw recorder settings of one capture, all checked."""

    definition: CaptureDefinition
    channels: tuple[PlannedChannel, ...]
    base_period_ns: int
    multiplier: int
    depth: int
    pre_trigger: int
    trigger_mode: int
    trigger_source: int  # 1..4: channel n; else a source pointer (immediate: 1, unused)
    trigger_variable: Variable | None
    trigger_level: int
    trigger_edge: int
    rearm: int
    auto_timeout_ms: int

    @property
    def period_ns(self) -> int:
        return self.base_period_ns * self.multiplier

    @property
    def record_size(self) -> int:
        return sum(channel.size for channel in self.channels)

    @property
    def total_bytes(self) -> int:
        return self.depth * self.record_size


def recorder_of(drive: Drive) -> RecorderDescription:
    """The drive's recorder description; a drive without one is refused (its captures use TPDOs or polling)."""
    recorder = drive.profile.recorder
    if recorder is None or drive.dictionary is None:
        raise NoRecorder(
            f"node {drive.node} ({drive.profile.device}): no recorder; its captures go through TPDOs at the "
            "server's SYNC or by polling (source tpdo or poll)"
        )
    return recorder


def plan_capture(
    drive: Drive, recorder: RecorderDescription, limits: RecorderLimits, definition: CaptureDefinition
) -> CapturePlan:
    """Check ``definition`` against the drive's dictionary and recorder; the plan, or the reason it cannot be."""
    channels = tuple(PlannedChannel(recordable(drive, split_channel(key)[0], "channel")) for key in definition.channels)
    if len(channels) > recorder.channels:
        raise CaptureRefused(f"{len(channels)} channels asked; the recorder has {recorder.channels}")
    multiplier = _multiplier(drive, recorder, limits, definition.period_us)
    record_size = sum(channel.size for channel in channels)
    depth = _depth(drive, recorder, limits, definition, record_size, limits.base_period_ns * multiplier)
    source, variable, level, edge = _trigger(drive, recorder, channels, definition)
    return CapturePlan(
        definition=definition,
        channels=channels,
        base_period_ns=limits.base_period_ns,
        multiplier=multiplier,
        depth=depth,
        pre_trigger=pre_trigger_samples(definition, depth),
        trigger_mode=recorder.trigger_modes["immediate" if definition.trigger.immediate else "edge"],
        trigger_source=source,
        trigger_variable=variable,
        trigger_level=level,
        trigger_edge=edge,
        rearm=recorder.rearm_modes[definition.mode],
        auto_timeout_ms=_auto_timeout(drive, recorder, definition.auto_timeout_ms),
    )


def recordable(drive: Drive, key: str, role: str) -> Variable:
    """The object ``key`` names, if the recorder can sample it (the rule of a TPDO mapping entry)."""
    try:
        variable = drive.variable(key)
    except UnknownObjectError as error:
        raise CaptureRefused(f"{role} {key!r}: {error}") from None
    if not (variable.pdo_mappable and variable.access.readable and variable.data_type in RECORDABLE_TYPES):
        raise CaptureRefused(
            f"{role} {key!r}: {variable.label} cannot be recorded: the recorder samples readable, PDO-mappable "
            "numbers of 8, 16 or 32 bits"
        )
    return variable


def _multiplier(drive: Drive, recorder: RecorderDescription, limits: RecorderLimits, period_us: float) -> int:
    period_ns, base = round(period_us * 1000), limits.base_period_ns
    if period_ns <= 0 or period_ns % base or abs(period_us * 1000 - period_ns) > 1e-6:
        examples = ", ".join(_us(base * n) for n in (1, 2, 3))
        raise CaptureRefused(
            f"period {number_text(period_us)} µs: the drive samples every multiple of its {_us(base)} µs base "
            f"period ({examples} µs, …)"
        )
    multiplier, highest = period_ns // base, _highest(drive, recorder, "multiplier")
    if multiplier > highest:
        raise CaptureRefused(f"period {number_text(period_us)} µs: the longest is {_us(highest * base)} µs")
    return multiplier


def _us(nanoseconds: int) -> str:
    return fixed_point_text(nanoseconds, 3)


def _physical(variable: Variable, raw: int | float) -> str:
    return number_text(round(variable.to_physical(raw), 9))


def _depth(
    drive: Drive,
    recorder: RecorderDescription,
    limits: RecorderLimits,
    definition: CaptureDefinition,
    record_size: int,
    period_ns: int,
) -> int:
    """Samples per channel: as asked, or the duration's worth; at most what the buffer holds for these channels."""
    fits = min(limits.capacity // record_size, _highest(drive, recorder, "depth"))
    if definition.samples is not None:
        depth, asked = definition.samples, f"{definition.samples} samples"
    elif definition.duration_s is not None:
        depth = math.ceil(round(definition.duration_s * 1e9 / period_ns, 6))
        asked = f"{number_text(definition.duration_s)} s ({depth} samples at {_us(period_ns)} µs)"
    else:
        return min(DEFAULT_SAMPLES, fits)
    if depth < 2:
        raise CaptureRefused(f"{asked}: a capture needs at least 2 samples")
    if depth > fits:
        raise CaptureRefused(
            f"{asked} do not fit the recorder: {limits.capacity} bytes hold {fits} samples of "
            f"{record_size} bytes ({len(definition.channels)} channels); fewer or smaller channels allow more"
        )
    return depth


def _trigger(
    drive: Drive, recorder: RecorderDescription, channels: tuple[PlannedChannel, ...], definition: CaptureDefinition
) -> tuple[int, Variable | None, int, int]:
    """(source, its variable, raw level, edge code); an immediate capture has none."""
    trigger = definition.trigger
    if trigger.source is None:
        return 1, None, 0, recorder.edges["rising"]
    variable = recordable(drive, trigger.source, "trigger source")
    numbers = [number for number, channel in enumerate(channels, 1) if channel.variable.key == variable.key]
    source = numbers[0] if numbers else PlannedChannel(variable).pointer
    return source, variable, raw_level(variable, trigger.edge, trigger.level), recorder.edges[trigger.edge]


def raw_level(variable: Variable, edge: str, level: float) -> int:
    """The level as the recorder compares it (raw, signed 32 bits), refused when the source can never cross it."""
    raw = round(variable.from_physical(level))
    low, high = variable.minimum, variable.maximum
    assert low is not None and high is not None  # a recordable type has a range
    crossable = {"rising": low < raw <= high, "falling": low <= raw < high, "either": low <= raw <= high and low < high}
    unit = f" {variable.unit}" if variable.unit else ""
    if not crossable[edge]:
        span = f"{_physical(variable, low)}..{_physical(variable, high)}{unit}"
        raise CaptureRefused(
            f"trigger level {number_text(level)}{unit} on {variable.label} can never fire {edge}: "
            f"the source takes {span}"
        )
    if not LEVEL_RANGE[0] <= raw <= LEVEL_RANGE[1]:
        raise CaptureRefused(
            f"trigger level {number_text(level)}{unit} on {variable.label} is raw {raw}, "
            "beyond the recorder's signed 32-bit level"
        )
    return raw


def pre_trigger_samples(definition: CaptureDefinition, depth: int) -> int:
    if definition.trigger.immediate:
        if definition.pre_trigger_pct:
            raise CaptureRefused("a pre-trigger needs a trigger: an immediate capture starts at the arm")
        return 0
    pre_trigger = round(depth * definition.pre_trigger_pct / 100)
    if pre_trigger > depth - 1:
        raise CaptureRefused(
            f"pre-trigger {number_text(definition.pre_trigger_pct)} % of {depth} samples "
            "leaves no room for the trigger sample"
        )
    return pre_trigger


def _auto_timeout(drive: Drive, recorder: RecorderDescription, milliseconds: int) -> int:
    variable = drive.variable(recorder.address("auto_timeout"))
    low, high = variable.minimum, variable.maximum
    if (low is not None and milliseconds < low) or (high is not None and milliseconds > high):
        raise CaptureRefused(f"auto timeout {milliseconds} ms: use {low}..{high} ms")
    return milliseconds


def _highest(drive: Drive, recorder: RecorderDescription, name: str) -> int:
    """The dictionary's upper limit of a recorder setting (the drive would refuse more)."""
    highest = drive.variable(recorder.address(name)).maximum
    assert isinstance(highest, int)
    return highest
