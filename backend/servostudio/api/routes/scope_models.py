"""The REST contract of the oscilloscope: a capture definition as a client sends it, and a capture as it comes back
(physical values per channel; time of sample i = (i − trigger_index) × period_ns, 0 = the trigger)."""

from __future__ import annotations

import math
from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field

from servostudio.api.routes.comm_models import JobModel
from servostudio.services.scope import Capture, CaptureDefinition, ChannelInfo, SavedCapture, Trigger
from servostudio.services.scope.multi import MultiPlan
from servostudio.services.scope.plan import CapturePlan
from servostudio.services.scope.stream_plan import StreamPlan

#: an object as a client names it: address (0x606C,0), name or profile name
ObjectName = Annotated[str, Field(min_length=1, max_length=80)]


class TriggerModel(BaseModel):
    model_config = ConfigDict(extra="forbid")
    source: str | None = Field(
        None, min_length=1, max_length=80, description="object or channel that triggers; none: immediate"
    )
    edge: Literal["rising", "falling", "either"] = "rising"
    level: float = Field(0.0, ge=-1e12, le=1e12, description="in the source's physical unit")


class CaptureRequest(BaseModel):
    """A capture definition; the drive's dictionary and recorder check it before anything is armed."""

    model_config = ConfigDict(
        extra="forbid",
        json_schema_extra={
            "examples": [
                {
                    "channels": ["0x60FF,0", "0x606C,0", "0x6078,0", "0x6041,0"],
                    "period_us": 250,
                    "samples": 2048,
                    "trigger": {"source": "0x606C,0", "edge": "rising", "level": 20480},
                    "pre_trigger_pct": 20,
                    "mode": "single",
                }
            ]
        },
    )
    channels: list[ObjectName] = Field(min_length=1, max_length=16, description="objects by address or name")
    period_us: float = Field(250.0, gt=0, le=1e9, description="a multiple of the drive's base period")
    samples: int | None = Field(None, ge=1, le=1_000_000, description="depth; else from duration_s, else the buffer")
    duration_s: float | None = Field(None, gt=0, le=1e6)
    trigger: TriggerModel = Field(default_factory=lambda: TriggerModel.model_validate({}))
    pre_trigger_pct: float = Field(0.0, ge=0, le=100)
    mode: Literal["single", "normal", "auto"] = "single"
    auto_timeout_ms: int = Field(100, ge=0, le=10**9)
    timeout_s: float | None = Field(None, gt=0, le=86400, description="give up when no recording completes by then")
    source: Literal["auto", "recorder", "tpdo", "poll"] = Field(
        "auto", description="the drive's recorder, synchronous TPDOs at the server's SYNC, or SDO polling"
    )

    def definition(self) -> CaptureDefinition:
        fields = self.model_dump()
        fields["channels"] = tuple(self.channels)
        fields["trigger"] = Trigger(**self.trigger.model_dump())
        return CaptureDefinition(**fields)

    @classmethod
    def of(cls, definition: CaptureDefinition) -> CaptureRequest:
        return cls.model_validate(definition.as_dict())


class PresetModel(BaseModel):
    key: str
    title: str
    description: str
    definition: CaptureRequest


class ScopeInfo(BaseModel):
    """The drive's recorder (or, without one, the TPDO capture's limits): its status and the presets it can run."""

    source: Literal["recorder", "tpdo", "poll"] = Field(description="how this drive's captures are taken")
    channels: int
    capacity: int | None = Field(description="bytes of one recording (none without a recorder)")
    base_period_ns: int = Field(description="the shortest period: the control period, or the server's 1 ms SYNC")
    status: str
    presets: list[PresetModel]


class RecorderStatus(BaseModel):
    status: str = Field(description="idle, filling, waiting, recording or done")
    counter: int = Field(description="recordings completed (wraps at 65536)")
    job: str | None = Field(None, description="the node's capture job while it runs")


class ChannelModel(BaseModel):
    key: str = Field(examples=["0x606C,0"])
    name: str
    unit: str
    data_type: str
    scale: float
    offset: float


class TpdoUseModel(BaseModel):
    node: int
    tpdo: int = Field(description="the TPDO's number, 1-based")
    channels: int


class StreamPlanModel(BaseModel):
    """A capture without the recorder: the rate and the bus load it will make, stated before arming."""

    rate_hz: float
    min_period_ns: int = Field(description="the shortest period this capture could have")
    frames_per_s: float
    bus_load: float = Field(description="share of the bus (worst-case stuff bits), 0..1")
    bitrate: int
    bitrate_assumed: bool = Field(description="the bus spec does not give the bit rate: 1 Mbit/s assumed")
    nodes: list[int]
    tpdos: list[TpdoUseModel]
    alignment: str = Field(description="how the channels and axes line up in time")


class PlanModel(BaseModel):
    """A definition the drive accepts, as the recorder (or the TPDOs, or polling) will run it."""

    source: Literal["recorder", "tpdo", "poll"]
    channels: list[ChannelModel]
    period_ns: int
    samples: int
    pre_trigger: int
    multiplier: int | None = Field(default=None, description="recorder: periods of the base period per sample")
    record_size: int | None = Field(default=None, description="recorder: bytes per record")
    bytes: int | None = Field(default=None, description="recorder: bytes of the recording")
    stream: StreamPlanModel | None = Field(
        default=None, description="TPDO and polled captures: rate, bus load, alignment"
    )


class DriveIdentityModel(BaseModel):
    bus: str
    node: int
    device: str
    product_name: str
    vendor_id: int | None
    product_code: int | None
    revision: int | None
    serial_number: int | None
    software_version: str | None


class CaptureModel(BaseModel):
    id: str | None = Field(None, description="the server's id of a live capture (it keeps the latest ones)")
    name: str | None = Field(None, description="the name of a capture saved in a project")
    definition: CaptureRequest
    channels: list[ChannelModel]
    period_ns: int
    samples: int
    trigger_index: int = Field(description="the trigger sample: time 0")
    trigger: str
    values: list[list[float | None]] = Field(description="physical values, one list per channel")
    drive: DriveIdentityModel
    captured_at: str
    source: str
    alignment_ns: int | None = Field(
        None, description="TPDO and polled captures: the largest distance of a sample from its instant"
    )


class SaveRequest(BaseModel):
    model_config = ConfigDict(extra="forbid")
    capture: str = Field(min_length=1, max_length=64, description="id of a live capture")
    name: str | None = Field(None, min_length=1, max_length=64, description="default: the time of capture")


class SavedCaptureModel(BaseModel):
    name: str
    captured_at: str
    channels: list[str]
    samples: int
    period_ns: int
    trigger: str
    source: str
    error: str | None = Field(None, description="why the capture cannot be read (file and line)")


def capture_model(capture: Capture, capture_id: str | None = None) -> CaptureModel:
    return CaptureModel(
        id=capture_id,
        name=capture.name or None,
        definition=CaptureRequest.of(capture.definition),
        channels=[ChannelModel(**vars(channel)) for channel in capture.channels],
        period_ns=capture.period_ns,
        samples=capture.samples,
        trigger_index=capture.trigger_index,
        trigger=capture.trigger,
        values=[[_finite(value) for value in capture.physical(n)] for n in range(len(capture.channels))],
        drive=DriveIdentityModel(**vars(capture.drive)),
        captured_at=capture.captured_at,
        source=capture.source,
        alignment_ns=capture.alignment_ns,
    )


def _finite(value: float) -> float | None:
    """JSON has no NaN or infinity (a REAL32 channel may hold them): those samples are null."""
    return value if math.isfinite(value) else None


def saved_model(saved: SavedCapture) -> SavedCaptureModel:
    fields = vars(saved) | {"channels": list(saved.channels)}
    return SavedCaptureModel(**fields)


def plan_model(plan: CapturePlan | StreamPlan | MultiPlan) -> PlanModel:
    """The plan as the check route answers it."""
    if isinstance(plan, MultiPlan):
        return _multi_model(plan)
    if isinstance(plan, StreamPlan):
        preview = plan.describe()
        return PlanModel(
            source=plan.source,  # type: ignore[arg-type]
            channels=[ChannelModel(**(vars(ChannelInfo.of(ch.variable)) | {"key": ch.key})) for ch in plan.channels],
            period_ns=plan.period_ns,
            samples=plan.depth,
            pre_trigger=plan.pre_trigger,
            stream=StreamPlanModel.model_validate(preview),
        )
    return PlanModel(
        source="recorder",
        channels=[ChannelModel(**vars(ChannelInfo.of(channel.variable))) for channel in plan.channels],
        period_ns=plan.period_ns,
        samples=plan.depth,
        pre_trigger=plan.pre_trigger,
        multiplier=plan.multiplier,
        record_size=plan.record_size,
        bytes=plan.total_bytes,
    )


def _multi_model(plan: MultiPlan) -> PlanModel:
    """A recorder capture of several axes: the channels in the capture's order (``OBJ@NODE`` of other axes), the
    sizes summed over the axes' recorders."""
    channels: list[ChannelModel | None] = [None] * len(plan.definition.channels)
    for axis in plan.axes:
        suffix = "" if axis.drive.node == plan.node else f"@{axis.drive.node}"
        for position, channel in zip(axis.positions, axis.plan.channels, strict=True):
            info = vars(ChannelInfo.of(channel.variable))
            channels[position] = ChannelModel(**(info | {"key": info["key"] + suffix}))
    return PlanModel(
        source="recorder",
        channels=[channel for channel in channels if channel is not None],
        period_ns=plan.period_ns,
        samples=plan.depth,
        pre_trigger=0,
        multiplier=plan.axes[0].plan.multiplier,
        record_size=sum(axis.plan.record_size for axis in plan.axes),
        bytes=sum(axis.plan.total_bytes for axis in plan.axes),
    )


class RollRequest(BaseModel):
    """Live roll mode: up to 4 channels per axis (``OBJ@NODE`` for another axis of the bus) through synchronous
    TPDOs at the server's SYNC; the bus budget is checked before anything is armed (422 when over-subscribed)."""

    model_config = ConfigDict(
        extra="forbid",
        json_schema_extra={"examples": [{"channels": ["0x6064,0", "0x606C,0"], "period_us": 1000, "record": True}]},
    )
    channels: list[ObjectName] = Field(min_length=1, max_length=16, description="objects by address or name")
    period_us: float = Field(1000.0, gt=0, le=1e9, description="the SYNC period: 1000 µs (1 kHz) at the fastest")
    seconds: float | None = Field(None, gt=0, le=86400, description="roll this long; none: until stopped")
    record: bool = Field(False, description="keep every sample (up to the first gap) as a capture at the end")

    def definition(self) -> CaptureDefinition:
        return CaptureDefinition(tuple(self.channels), period_us=self.period_us, source="tpdo")


class RollModel(BaseModel):
    """A roll started: its job (``scope-roll``), the plan with the bus budget, and the WebSocket of its samples."""

    job: JobModel
    plan: PlanModel
    socket: str = Field(description="GET as WebSocket: the roll's samples, gaps and end (docs/scope.md §8)")
