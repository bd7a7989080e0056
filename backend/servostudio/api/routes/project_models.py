"""Pydantic models of the project API (the contract); the dict views they are built from are shared with the CLI."""

from __future__ import annotations

from pydantic import BaseModel, Field

from servostudio.services.projects import Bus, ParameterRow, Snapshot
from servostudio.services.projects.jsonview import parameter_view, project_view


class BusModel(BaseModel):
    name: str = Field(examples=["sim"])
    interface: str = Field(examples=["sim", "socketcan:can0"])
    bitrate: int | None = Field(default=None, examples=[1000000])


class AxisModel(BaseModel):
    name: str = Field(examples=["X"])
    device: str = Field(examples=["xtrapulspac"])
    node_id: int = Field(examples=[1])
    bus: str = Field(examples=["sim"])
    description: str = ""
    motor: str = ""
    application: str = ""


class ProjectModel(BaseModel):
    name: str
    description: str
    buses: list[BusModel]
    axes: list[AxisModel]
    revision: str = Field(description="pass back with the next change (optimistic concurrency)")


class ProjectSummary(BaseModel):
    name: str
    description: str
    axis_count: int
    revision: str
    error: str | None = Field(description="why the project cannot be opened; null when it is fine")


class ProjectCreate(BaseModel):
    name: str
    description: str = ""
    buses: list[BusModel] = []


class ProjectUpdate(BaseModel):
    description: str | None = None
    buses: list[BusModel] | None = None
    revision: str | None = None


class NewName(BaseModel):
    new_name: str
    revision: str | None = None


class AxisCreate(AxisModel):
    revision: str | None = None


class AxisUpdate(BaseModel):
    name: str | None = None
    device: str | None = None
    node_id: int | None = None
    bus: str | None = None
    description: str | None = None
    revision: str | None = None


Scalar = int | float | str | None


class ParameterModel(BaseModel):
    index: int
    subindex: int
    name: str = Field(description="e.g. '0x60F9,2 Speed loop gains.KPv'")
    group: str
    data_type: str
    access: str
    save_type: str
    unit: str
    value: Scalar = Field(description="project value: set in the axis files, else the default (raw units)")
    default: Scalar
    differs_from_default: bool
    file: str | None = Field(description="DRIVEPAR.TXT / USER_PAR.TXT when the project sets it, else null")
    editable: bool
    not_editable_reason: str | None


class ParameterList(BaseModel):
    parameters: list[ParameterModel]
    revision: str


class ValueChangeModel(BaseModel):
    index: int
    subindex: int
    name: str
    unit: str
    old: Scalar
    new: Scalar


class DcfImportModel(BaseModel):
    parameters: list[ParameterModel] = Field(description="the objects the DCF's configured values set")
    changes: list[ValueChangeModel] = Field(description="the project values that change, old and new")
    skipped: list[str] = Field(description="configured values the project cannot hold, each with its reason")
    revision: str = Field(description="the new revision; with dry_run, the current one (nothing was written)")


class ParameterWrite(BaseModel):
    values: dict[str, int | float | str] = Field(examples=[{"0x6060": -3, "0x60F9,2": 1200}])
    revision: str | None = None
    keep_revision: bool = Field(
        default=False,
        description="keep the project as it was before this change restorable (GET/POST …/revisions): "
        "for a change that replaces many values, such as a backup of the drive into the project",
    )


class KeptRevisionModel(BaseModel):
    revision: str = Field(description="the project's revision before the change that replaced it")
    saved_at: float = Field(description="when it was replaced (epoch seconds)")
    reason: str = Field(description="what replaced it")
    files: int
    by: str = Field(description="who made the change that replaced it (empty when not recorded)")


class RevisionRestore(BaseModel):
    revision: str | None = Field(default=None, description="the project's current revision (refused if it changed)")


class ParameterReset(BaseModel):
    addresses: list[str]
    revision: str | None = None


class CompareRowModel(BaseModel):
    index: int
    subindex: int
    name: str
    group: str
    unit: str
    values: dict[str, Scalar] = Field(
        description="column -> value; columns drive (with ?drive=true) / project / default"
    )
    differs: bool


class CompareModel(BaseModel):
    columns: list[str]
    rows: list[CompareRowModel]
    revision: str
    refused: dict[str, str] = Field(default={}, description="objects the drive refused to read: address -> reason")
    read_only: list[CompareRowModel] = Field(
        default=[],
        description="with ?read_only=true: the read-only entries (error register, status word, measurements), "
        "apart from rows and never counted as differences: nobody writes or restores them",
    )


class AxisChoiceModel(BaseModel):
    changed: list[ParameterModel]
    notes: list[str] = Field(description="consequences not reproduced offline, or reproduced without some inputs")
    project: ProjectModel


class MotorChoice(BaseModel):
    reference: str
    revision: str | None = None
    drive: bool = Field(
        default=False, description="write the motor to the axis's live drive and read back what the drive derived"
    )


class TemplateChoice(BaseModel):
    template: str = Field(examples=["analog-speed", "positioner", "stepper-emulation", "expert"])
    revision: str | None = None


class SettingModel(BaseModel):
    index: int
    subindex: int
    value: int
    why: str


class TemplateModel(BaseModel):
    key: str
    title: str
    description: str
    settings: list[SettingModel]
    groups: list[str] | None = Field(description="parameter groups the UI shows; null = all (Expert mode)")


class MotorModel(BaseModel):
    reference: str
    description: str = ""
    source: str = ""
    motor_data: dict[str, int | str] = Field(description="0x6410 sub-entries by name, raw object units")
    objects: dict[str, int | float | str] = Field(default={}, description='other objects, keys like "0x3324,1"')
    builtin: bool = False


# ---- conversions (the dict views are shared with the CLI) ---------------------------------------------------------


def project_model(snapshot: Snapshot) -> ProjectModel:
    return ProjectModel(**project_view(snapshot))


def parameter_model(row: ParameterRow) -> ParameterModel:
    return ParameterModel(**parameter_view(row))


def buses_from(models: list[BusModel]) -> tuple[Bus, ...]:
    return tuple(Bus(b.name, b.interface, b.bitrate) for b in models)
