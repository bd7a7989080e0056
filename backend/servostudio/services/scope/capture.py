"""A capture as the tool keeps it: raw channel values as the drive recorded them, with what turns them into physical
values (unit, scale, offset from the dictionary), the time axis (time 0 = the trigger), the definition it was made
with and the drive it came from.

Raw values are the truth (a saved capture re-opens to exactly the recorded numbers); physical values and times are
computed from them the one way everything shows them (CSV, JSON, HTML, the page).
"""

from __future__ import annotations

import struct
from collections.abc import Iterable
from dataclasses import dataclass, field
from datetime import UTC, datetime

from servostudio.od.datatypes import DataType
from servostudio.od.model import Variable
from servostudio.services.scope.definition import CaptureDefinition
from servostudio.services.scope.plan import CapturePlan, object_key

#: little-endian ``struct`` codes of the recordable types (each equals ``od.encode``)
FORMATS = {
    DataType.INTEGER8: "b",
    DataType.INTEGER16: "h",
    DataType.INTEGER32: "i",
    DataType.UNSIGNED8: "B",
    DataType.UNSIGNED16: "H",
    DataType.UNSIGNED32: "I",
    DataType.REAL32: "f",
}
MAX_DECIMALS = 12
Number = int | float


@dataclass(frozen=True)
class ChannelInfo:
    """One recorded object and how its raw values become physical ones: ``raw × scale + offset`` in ``unit``."""

    key: str
    name: str
    unit: str
    data_type: str
    scale: float = 1.0
    offset: float = 0.0

    @classmethod
    def of(cls, variable: Variable) -> ChannelInfo:
        name = f"{variable.parent_name}.{variable.name}" if variable.parent_name not in ("", variable.name) else ""
        return cls(
            object_key(variable),
            name or variable.name,
            variable.unit,
            DataType(variable.data_type).name,
            variable.scale,
            variable.offset,
        )

    @property
    def type(self) -> DataType:
        return DataType[self.data_type]

    @property
    def decimals(self) -> int:
        """The decimals a physical value needs to show every raw step exactly (0.1 → 1, 0.0625 → 4)."""
        return next(
            (
                d
                for d in range(MAX_DECIMALS)
                if round(self.scale, d) == self.scale and round(self.offset, d) == self.offset
            ),
            MAX_DECIMALS,
        )

    def physical(self, raw: Number) -> Number:
        if self.scale == 1.0 and self.offset == 0.0:
            return raw
        value = round(raw * self.scale + self.offset, self.decimals)
        return int(value) if self.decimals == 0 and not self.type.is_float else value

    def physical_all(self, raws: Iterable[Number]) -> list[Number]:
        """`physical` of every raw value, the decimals worked out once, not per value (a roll converts 12,000
        values a second)."""
        if self.scale == 1.0 and self.offset == 0.0:
            return list(raws)
        scale, offset, decimals = self.scale, self.offset, self.decimals
        if decimals == 0 and not self.type.is_float:
            return [int(round(raw * scale + offset, 0)) for raw in raws]
        return [round(raw * scale + offset, decimals) for raw in raws]

    def raw_of(self, physical: float) -> Number:
        """The raw value a physical one came from (the inverse of `physical`)."""
        raw = (physical - self.offset) / self.scale
        return struct.unpack("<f", struct.pack("<f", raw))[0] if self.type.is_float else round(raw)


@dataclass(frozen=True)
class DriveIdentity:
    """The drive a capture came from, as the scan identified it."""

    bus: str
    node: int
    device: str
    product_name: str = ""
    vendor_id: int | None = None
    product_code: int | None = None
    revision: int | None = None
    serial_number: int | None = None
    software_version: str | None = None

    def describe(self) -> str:
        """One line for the CSV's ``drive:`` comment."""
        numbers = (
            ("vendor", self.vendor_id),
            ("product", self.product_code),
            ("revision", self.revision),
            ("serial", self.serial_number),
        )
        parts = [f"{name} 0x{value:08X}" for name, value in numbers if value is not None]
        if self.software_version:
            parts.append(f"software {self.software_version}")
        head = " ".join(part for part in (self.device, self.product_name) if part)
        return f"{head} ({', '.join(parts)})" if parts else head


@dataclass(frozen=True)
class Capture:
    definition: CaptureDefinition
    channels: tuple[ChannelInfo, ...]
    period_ns: int
    trigger_index: int
    trigger: str  # the trigger as shown: "0x606C,0 rising 20480 user unit/s" or "immediate"
    columns: tuple[tuple[Number, ...], ...]  # raw values, one tuple per channel
    drive: DriveIdentity
    captured_at: str  # ISO 8601, UTC
    source: str = "recorder"
    name: str = field(default="", compare=False)  # the saved capture's name in its project (empty: not saved)
    #: TPDO and polled captures: the largest distance of a sample from its instant (SYNC jitter, a poll's reads);
    #: recorder captures of several axes: the largest offset between two axes' samples (multi.py)
    alignment_ns: int | None = field(default=None, compare=False)

    @property
    def samples(self) -> int:
        return len(self.columns[0]) if self.columns else 0

    @property
    def pre_trigger(self) -> int:
        """Samples before the trigger sample (fewer than planned when the trigger was forced early)."""
        return self.trigger_index

    def time_ns(self, sample: int) -> int:
        return (sample - self.trigger_index) * self.period_ns

    def times_s(self) -> list[float]:
        return [self.time_ns(sample) / 1e9 for sample in range(self.samples)]

    def physical(self, channel: int) -> list[Number]:
        return self.channels[channel].physical_all(self.columns[channel])


def decode_recording(plan: CapturePlan, data: bytes) -> tuple[tuple[Number, ...], ...]:
    """The recording's bytes → one tuple of raw values per channel (records hold the channels in order)."""
    layout = struct.Struct("<" + "".join(FORMATS[channel.variable.data_type] for channel in plan.channels))
    records = list(layout.iter_unpack(data))
    return tuple(zip(*records, strict=True)) if records else tuple(() for _ in plan.channels)


def build_capture(
    plan: CapturePlan,
    data: bytes,
    trigger_index: int,
    drive: DriveIdentity,
    when: datetime | None = None,
) -> Capture:
    trigger = plan.definition.trigger
    unit = plan.trigger_variable.unit if plan.trigger_variable is not None else ""
    source = object_key(plan.trigger_variable) if plan.trigger_variable is not None else None
    return Capture(
        definition=plan.definition,
        channels=tuple(ChannelInfo.of(channel.variable) for channel in plan.channels),
        period_ns=plan.period_ns,
        trigger_index=trigger_index,
        trigger=type(trigger)(source, trigger.edge, trigger.level).describe(unit),
        columns=decode_recording(plan, data),
        drive=drive,
        captured_at=(when or datetime.now(UTC)).isoformat(timespec="seconds").replace("+00:00", "Z"),
    )
