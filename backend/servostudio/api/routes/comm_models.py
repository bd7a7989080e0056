"""Pydantic models of the communication API (buses, drives, backup); the examples appear in the OpenAPI schema."""

from __future__ import annotations

from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field


def _example(**values: Any) -> ConfigDict:
    return ConfigDict(json_schema_extra={"examples": [values]})


class BusOpen(BaseModel):
    model_config = _example(spec="socketcand:127.0.0.1:29536", id="line1")
    spec: str = Field(
        description="bus spec: socketcan:can0, pcan:PCAN_USBBUS1@1000000, ixxat:0@500000, kvaser:0, "
        "slcan:/dev/ttyACM0@1000000, socketcand:HOST:PORT[/CH], virtual:NAME, "
        "serial:PORT_OR_URL[@BAUD], profibus:PORT[@BAUD][?master=ADDR] (PORT a serial device, socket://HOST:PORT "
        "or tcp:HOST:PORT), sim[:NODES]"
    )
    id: str | None = Field(
        None, description="name of the bus in later calls (default: the bus kind, e.g. sim, socketcand, socketcand2, …)"
    )


class NodeIdentity(BaseModel):
    model_config = _example(
        node=1,
        device="xtrapulspac",
        device_type=131474,
        vendor_id=130,
        product_code=1481654595,
        revision=0,
        serial_number=0,
        device_name="XtrapulsPac",
        hardware_version="",
        software_version="",
    )
    node: int
    device: str | None = None
    device_type: int | None = None
    vendor_id: int | None = None
    product_code: int | None = None
    revision: int | None = None
    serial_number: int | None = None
    device_name: str | None = None
    hardware_version: str | None = None
    software_version: str | None = None


class BusStatus(BaseModel):
    model_config = _example(id="sim", spec="sim", kind="sim", connected=True, error=None, nodes=[])
    id: str
    spec: str
    kind: str
    connected: bool
    error: str | None = None
    nodes: list[NodeIdentity] = []


class ProjectBusRef(BaseModel):
    name: str = Field(max_length=200, description="the project's name of the bus")
    spec: str = Field(max_length=1000, description="the project's spec of the bus (its interface)")


class BusMatchRequest(BaseModel):
    model_config = _example(buses=[{"name": "line1", "spec": "socketcand:127.0.0.1:29536"}])
    buses: list[ProjectBusRef] = Field(max_length=256)


class BusMatchModel(BaseModel):
    name: str
    spec: str
    bus: str | None = Field(description="the open bus it is (null: not open)")
    by: Literal["name", "spec", "name_only"] | None = Field(
        description="name: same name and spec; spec: its spec is open under another name; name_only: the open bus "
        "of that name has another spec"
    )


class OpenedBus(BusStatus):
    existing: bool = Field(description="the spec was open already (answered 200, under its own name)")


class ShareRequest(BaseModel):
    model_config = _example(host="127.0.0.1", port=29540)
    host: str = Field("127.0.0.1", max_length=100, description="a loopback address (127.0.0.1, ::1, localhost)")
    port: int = Field(0, ge=0, le=65535, description="TCP port; 0: any free port (the answer names it)")


class ShareModel(BaseModel):
    model_config = _example(bus="sim", host="127.0.0.1", port=29540, channel="can0", clients=1, dropped=0)
    bus: str
    host: str
    port: int
    channel: str = Field(description="the socketcand channel a client opens")
    clients: int = Field(description="clients connected now")
    dropped: int = Field(description="client frames not put on the bus (PDOs and others; SDO and NMT pass)")


class NmtRequest(BaseModel):
    model_config = _example(command="start", node=0)
    command: str = Field(description="start | stop | pre-operational | reset-node | reset-communication")
    node: int = Field(0, ge=0, le=127, description="0 = every node")


class BitValue(BaseModel):
    name: str
    first: int
    last: int
    value: int


class ObjectValueModel(BaseModel):
    model_config = _example(
        node=1,
        index=0x6060,
        sub=0,
        name="Modes of operation",
        label="0x6060,0 Modes of operation",
        data_type="INTEGER8",
        access="rw",
        raw=1,
        physical=1,
        unit="",
        text="Profile position",
        bits=[],
    )
    node: int
    index: int
    sub: int
    name: str
    label: str
    data_type: str
    access: str
    raw: int | float | str
    physical: int | float | str
    unit: str
    text: str
    bits: list[BitValue] = []


class ObjectWrite(BaseModel):
    model_config = _example(value="Profile position", physical=False)
    value: int | float | str = Field(description="number, 0x hex text, enumeration label, or text for strings")
    physical: bool = Field(False, description="value is in the object's unit (raw = (value - Offset) / Scale)")


class ReadMany(BaseModel):
    model_config = _example(objects=["statusword", "0x6060", "0x60F9,2"])
    objects: list[str] = Field(max_length=256)


class ReadResult(BaseModel):
    object: str
    value: ObjectValueModel | None = None
    error: str | None = None


class StateRequest(BaseModel):
    model_config = _example(target="operation-enabled")
    target: str = Field(
        description="switch-on-disabled | ready-to-switch-on | switched-on | operation-enabled | quick-stop-active"
    )


class DriveState(BaseModel):
    model_config = _example(node=1, state="SWITCH ON DISABLED", statusword=0x0240, nmt_state="PRE-OPERATIONAL")
    node: int
    state: str | None
    statusword: int
    nmt_state: str | None = Field(None, description="as the node's heartbeat or boot-up said it (null: none seen)")
    nmt_source: Literal["heartbeat", "sdo"] | None = Field(
        None, description="heartbeat: nmt_state is the node's own; sdo: only known to answer SDO (pre-op or op)"
    )
    nmt_text: str = Field("", description="what is known, for display (e.g. 'PRE-OPERATIONAL or OPERATIONAL')")


class FaultInfoModel(BaseModel):
    code: int
    cia402_code: int
    name: str
    remedy: str


class FaultCauseModel(BaseModel):
    """An object a failed procedure needed, seen at 0 or out of its range: the cause the drive does not report."""

    object: str = Field(examples=["0x6410,11 Motor data.Torque constant"])
    value: int | float
    problem: str = Field(examples=["is 0", "is outside 1..24"])
    needed_by: str = Field(examples=["auto-tuning"])


class FaultReportModel(BaseModel):
    model_config = _example(
        node=1,
        state="FAULT",
        statusword=0x0208,
        fault=True,
        error_code=0x8611,
        error_text="following error",
        faults=[
            {"code": 35, "cia402_code": 0x8611, "name": "Position following error", "remedy": "Check that the load …"}
        ],
        warnings=[],
    )
    node: int
    state: str | None
    statusword: int
    fault: bool
    error_code: int
    error_text: str
    faults: list[FaultInfoModel]
    warnings: list[FaultInfoModel]
    causes: list[FaultCauseModel] = Field(
        default_factory=list, description="what the tool sees behind a procedure fault (empty: nothing it can see)"
    )


class BackupRequest(BaseModel):
    model_config = _example(directory="projects/line1/backup", nodes=[1, 2], files=["DRIVEPAR.TXT"])
    directory: str = Field(description="server-side directory; each node's files go to DIRECTORY/node<N>/")
    nodes: list[int] | None = Field(None, description="default: every node found by the last scan")
    files: list[str] | None = Field(
        None, description="DRIVEPAR.TXT, USER_PAR.TXT, SEQUENCE.TXT (default: all the device has)"
    )


class RestoreRequest(BackupRequest):
    store: bool = Field(True, description="store to flash after a verified restore (0x1010 'save')")


class JobModel(BaseModel):
    model_config = _example(
        id="job1", operation="backup", state="running", result=None, error=None, started=1763771000.0, finished=None
    )
    id: str
    operation: str
    state: str
    result: Any = None
    error: str | None = None
    started: float
    finished: float | None = None
