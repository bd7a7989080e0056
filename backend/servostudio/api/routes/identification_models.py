"""The identification's REST contract (docs/identification.md)."""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field

from servostudio.services.identification import IdentificationRequest


class IdentificationOptions(BaseModel):
    """The experiment's options; each has a default (docs/identification.md § Experiment)."""

    model_config = ConfigDict(extra="forbid")
    speed_rpm: float | None = Field(default=None, ge=50, le=6000, description="the higher speed held, rpm")
    acceleration_rpm_s: float | None = Field(default=None, ge=500, le=200000, description="the ramps, rpm/s")
    hold_s: float | None = Field(
        default=None, ge=0.05, le=2, description="cruise at the higher speed, s (the lower: twice)"
    )
    position_window_rev: float | None = Field(
        default=None, ge=0.5, le=1000, description="revolutions either side of start"
    )
    current_limit_pct: float | None = Field(
        default=None, ge=10, le=300, description="current limit, % of the rated current"
    )
    cycles: int | None = Field(default=None, ge=1, le=5, description="repetitions of the profile")


class IdentificationStart(BaseModel):
    model_config = ConfigDict(
        extra="forbid", json_schema_extra={"examples": [{"options": {"speed_rpm": 800, "position_window_rev": 6}}]}
    )
    options: IdentificationOptions = Field(default_factory=IdentificationOptions)
    bandwidth_hz: float | None = Field(
        default=None, ge=20, le=200, description="then tune the speed loop for this bandwidth and verify it by a step"
    )

    def request(self) -> IdentificationRequest:
        return IdentificationRequest(self.options.model_dump(exclude_none=True), self.bandwidth_hz)
