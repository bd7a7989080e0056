"""The REST contract of the procedures (issue #13 contract): the procedures of a drive with their preconditions, a
start request, undo of an auto-tuning, saved results."""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, Field

from servostudio.services.procedures import ProcedureRequest

Status = Literal["never", "cannot", "running", "aborted", "error", "done", "unknown"]
ProjectName = Annotated[str, Field(min_length=1, max_length=120)]
OptionValue = Annotated[str, Field(max_length=40)] | float | None


class PreconditionModel(BaseModel):
    name: str = Field(examples=["disabled"], description="the check, or value:<object> for a value it needs")
    label: str = Field(examples=["Drive disabled"])
    ok: bool
    reason: str | None = Field(None, description="why not, in the manual's words; null when ok")


class ProcedureModel(BaseModel):
    name: str = Field(examples=["auto_tuning"])
    label: str = Field(examples=["Auto-tuning"])
    moves: bool = Field(description="turns the motor: needs the axis's armed controller (X-Servo-Client)")
    status: Status = Field(description="the trigger's read-back status now")
    preconditions: list[PreconditionModel]
    ready: bool = Field(description="every precondition is met")


class ProcedureStart(BaseModel):
    """Start a procedure; options per procedure (auto_tuning: bandwidth 50|75|100, filter standard|anti-resonance|
    max-stiffness, speed_filter auto|0.5|1|2, mode min-following-error|min-overshoot; current_loop: inductance_mh
    (phase to phase, written to the motor data first), regulator high|low)."""

    model_config = ConfigDict(
        extra="forbid",
        json_schema_extra={
            "examples": [{"options": {"bandwidth": 75, "filter": "standard"}, "verify": True, "project": None}]
        },
    )
    options: dict[Annotated[str, Field(max_length=40)], OptionValue] = Field(default_factory=dict, max_length=8)
    verify: bool = Field(True, description="run the verification (auto-phasing: commutation; auto-tuning: steps)")
    project: ProjectName | None = Field(None, description="save the result under this project's axis")
    axis: ProjectName | None = None

    def request(self) -> ProcedureRequest:
        return ProcedureRequest(dict(self.options), self.verify, self.project, self.axis)


class UndoRequest(BaseModel):
    model_config = ConfigDict(extra="forbid")
    gains: dict[Annotated[str, Field(max_length=40)], int] = Field(
        description="the `before` of an auto-tuning result: semantic name → raw value", max_length=32
    )


class UndoResult(BaseModel):
    gains: dict[str, Any] = Field(description="the gains as read back after the write")
