"""The REST contract of the sequence routes (``api/routes/sequences.py``)."""

from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, Field

PatternOrNumber = str | int | None


class SequenceText(BaseModel):
    text: str = Field(
        max_length=1_000_000, description="SEQUENCE.TXT (Latin-1 text)", examples=["SeqNb=1\nSeqType=POS\n"]
    )
    file: str = Field("SEQUENCE.TXT", max_length=200, description="the name messages give the file")


class IssueModel(BaseModel):
    file: str
    line: int
    keyword: str | None
    reason: str = Field(
        description="why, with the allowed range", examples=["value 200000 is out of range: allowed 1..65535"]
    )


class SequenceModel(BaseModel):
    sequence: int = Field(ge=0, le=127)
    type: str = Field(examples=["POS"])
    values: dict[str, PatternOrNumber] = Field(
        description="every parameter in the file's spelling: numbers, constants by name, patterns of 8 characters; "
        "null: a default the file cannot spell"
    )


class EdgeModel(BaseModel):
    model_config = {"populate_by_name": True}

    source: int = Field(alias="from")
    to: int
    kind: Literal["next", "link", "counter", "condition"]
    dangling: bool


class FindingModel(BaseModel):
    kind: Literal["loop_without_exit", "dangling", "unreachable", "counters", "unsupported_type"]
    sequences: list[int]
    message: str


class GraphNodeModel(BaseModel):
    sequence: int
    type: str
    supported: bool
    entry: bool
    reachable: bool
    waits: bool


class GraphModel(BaseModel):
    nodes: list[GraphNodeModel]
    edges: list[EdgeModel]
    findings: list[FindingModel]


class CheckModel(BaseModel):
    file: str
    ok: bool
    issues: list[IssueModel]
    sequences: list[SequenceModel] = Field(default_factory=list)
    graph: GraphModel | None = None


class KeywordModel(BaseModel):
    name: str
    aliases: list[str]
    subs: list[int]
    unit: str
    pattern: bool
    constants: list[str] | None
    allowed: list[list[int]] | None
    default: PatternOrNumber


class CatalogModel(BaseModel):
    types: list[str]
    keywords: dict[str, list[KeywordModel]]


class DriveSequencesModel(CheckModel):
    text: str = Field(description="the sequence memory as SEQUENCE.TXT")
    count: int = Field(description="0x3612: sequence numbers 0..count-1")
    types: list[str] = Field(description="0x360F: the types the drive supports")


class DownloadRequest(SequenceText):
    mode: Literal["load", "merge"] = Field("load", description="load: slots the file does not declare are cleared")
    store: bool = Field(False, description="store the verified memory to flash (sseq)")


class DownloadModel(BaseModel):
    node: int
    mode: str
    sequences: list[int]
    verified: bool
    mismatched: list[int]
    stored: bool
    seconds: float


class ReloadRequest(BaseModel):
    mode: Literal["load", "merge"] = "load"


class StartRequest(BaseModel):
    sequence: int = Field(ge=0, le=127)


class InputsRequest(BaseModel):
    conditional: str | None = Field(
        None, max_length=40, description='0x3601,3: a number or a pattern MSB first ("1......."; . keeps a bit)'
    )
    sim: str | None = Field(None, max_length=40, description="simulated drive only: IN5..IN1 (0x5F00), e.g. 10000")


class InputsModel(BaseModel):
    conditional: int = Field(description="0x3601,3 now (bits 0-15)")
    sim: int | None = Field(None, description="what was written to the simulated inputs")


class RunModel(BaseModel):
    node: int
    sequence: int | None = None
    started: bool = False
    stopped: bool = False
    state: str | None = None


class SampleModel(BaseModel):
    t: float = Field(description="seconds since the monitor started (the drive's clock between TPDOs)")
    sequence: int
    phase: str = Field(examples=["BEGIN", "CRUISE", "DECEL", "HOLD", "INPOS", "END", "WAIT", "IDLE"])


class CounterModel(BaseModel):
    sequence: int
    remaining: int


class MonitorModel(BaseModel):
    now: float = Field(description="seconds since the monitor started, on the clock of `t`")
    running: bool
    sequence: int
    phase: str
    phases: int = Field(description="0x3605")
    outputs: int = Field(description="0x3602,1")
    dedicated_outputs: int = Field(description="0x3602,3: POS, SEQ, SPEED, READY")
    counter: CounterModel | None = Field(description="the loop counter, counted by the monitor (no drive object)")
    captured_position: int | None = Field(description="0x360B")
    timeline: list[SampleModel] = Field(description="samples from index `since` on")
    next: int = Field(description="pass as `since` to get only newer samples")
    executed: list[SampleModel] = Field(description="one per executed sequence: when it began, its last phase")


class ProjectSequences(BaseModel):
    text: str
    revision: str


class ProjectSequencesWrite(SequenceText):
    revision: str | None = Field(None, description="the revision read; a changed project is refused (409)")
