"""The REST contract of the I/O routes (``api/routes/io.py``, docs/io.md)."""

from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, Field

Name = Field(max_length=40, description="the input or output as the page names it", examples=["IN3"])
FunctionKey = Field(None, max_length=60, description="a key of `functions` / `output_functions`")


class IoFunctionModel(BaseModel):
    key: str = Field(examples=["positive_limit"])
    label: str
    limit: int = Field(description="-1 / +1: the negative / positive limit switch, 0: another function")
    condition_bit: int | None = Field(description="the bit of the sequence conditional input 0x3601,3 it feeds")


class IoInputModel(BaseModel):
    name: str
    bit: int = Field(description="its bit in the input image 0x60FD")
    physical: bool
    function: str = Field(description="a function key, or 'other' for a destination no function names")
    pointer: int | None = Field(description="the destination pointer (XtrapulsPac 0x3050,n); null elsewhere")
    allowed: list[str]
    inverted: bool | None = Field(description="the polarity; null: the device has none")
    active: bool | None = Field(description="the input's state in 0x60FD (after its polarity)")


class IoOutputModel(BaseModel):
    name: str
    bit: int = Field(description="its bit in the output image 0x60FE,1")
    physical: bool
    function: str
    pointer: int | None
    inverted: bool | None
    active: bool | None


class IoSettingModel(BaseModel):
    key: str
    label: str
    address: str = Field(examples=["0x30F1,3"])
    value: int | None
    low: int | None
    high: int | None
    pointer: bool = Field(description="a dataflow pointer index << 16 | sub << 8 | bit-or-size")
    writable: bool


class IoGroupModel(BaseModel):
    key: str
    title: str
    settings: list[IoSettingModel]
    live: list[IoSettingModel]


class IoStateModel(BaseModel):
    inputs: int | None = Field(description="0x60FD")
    outputs: int | None = Field(description="0x60FE,1")
    negative_limit: bool | None
    positive_limit: bool | None
    home: bool | None
    inhibit: bool | None


class IoSimInputsModel(BaseModel):
    names: list[str]
    meaning: str
    value: int


class IoFindingModel(BaseModel):
    severity: Literal["unsafe", "warning", "note"]
    subject: str
    text: str


class IoModel(BaseModel):
    node: int
    device: str
    routing: Literal["pointer", "dedicated", "fixed"]
    note: str
    functions: list[IoFunctionModel]
    output_functions: list[IoFunctionModel]
    inputs: list[IoInputModel]
    outputs: list[IoOutputModel]
    groups: list[IoGroupModel]
    state: IoStateModel
    findings: list[IoFindingModel] = Field(description="the fail-safe check of the limit switches, and notes")
    simulated: IoSimInputsModel | None = Field(description="a simulated drive's test bench inputs (0x5F00)")
    written: list[str] = Field(default_factory=list, description="after a change: the objects written, in order")


class IoLiveModel(IoStateModel):
    input_levels: dict[str, bool | None]
    output_levels: dict[str, bool | None]
    analog: dict[str, int | None]
    simulated: IoSimInputsModel | None


class IoInputChangeModel(BaseModel):
    name: str = Name
    function: str | None = FunctionKey
    inverted: bool | None = None


class IoOutputChangeModel(BaseModel):
    name: str = Name
    function: str | None = FunctionKey
    inverted: bool | None = None


class IoChangeRequest(BaseModel):
    inputs: list[IoInputChangeModel] = Field(default_factory=list, max_length=32)
    outputs: list[IoOutputChangeModel] = Field(default_factory=list, max_length=32)
    settings: dict[str, int | str] = Field(
        default_factory=dict, max_length=64, description="setting key → value (pointers also as '0x30F80100')"
    )


class IoSimInputsRequest(BaseModel):
    value: int = Field(ge=0, le=0xFFFF, description="bit n: the test bench's input n (see `simulated.names`)")
