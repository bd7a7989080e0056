"""The speed loop in physical units as the REST API shows it (docs/what-if.md, contract of issue #16 §3)."""

from __future__ import annotations

from typing import Any

from pydantic import BaseModel, ConfigDict, Field

_GAIN = Field(default=None, ge=0.0, allow_inf_nan=False)


class SpeedLoopModel(BaseModel):
    """The speed loop read now: gains in A/(rad/s), A/rad, A/(rad/s²), filters in Hz, the speed filter in s."""

    model_config = ConfigDict(extra="allow")
    device: str
    control_period_s: float
    torque_constant_nm_per_a: float | None = Field(description="null: the drive has no torque-constant object")
    gain_multiplier: float = Field(description="KJv/256 (1 on a drive without multiplier)")
    kp_a_per_rad_s: float
    ki_a_per_rad: float
    ki_leak_hz: float
    kc_a_per_rad_s: float
    kd_a_per_rad_s2: float
    current_filters_hz: list[float] = Field(description="the drive's first-order current-command filters, 0 = off")
    speed_filter_s: float = Field(description="time constant of the speed-measurement filter")
    speed_filter_choices_s: list[float] = Field(
        default=[], description="the speed-filter time constants a PUT takes (empty: the filter is fixed)"
    )
    writable: list[str] = Field(description="the keys a PUT takes on this drive")
    inertia_setting_kgm2: float | None = Field(
        default=None,
        description="the inertia setting the drive derives its gains from (encoTRive Θi); null on other drives",
    )
    raw: dict[str, int] = Field(description="semantic object name → raw value read")


class SpeedLoopChange(BaseModel):
    """Physical values to write; keys left out keep their values.  The drive's `writable` says which it takes."""

    model_config = ConfigDict(extra="forbid")
    kp_a_per_rad_s: float | None = _GAIN
    ki_a_per_rad: float | None = _GAIN
    ki_leak_hz: float | None = _GAIN
    kc_a_per_rad_s: float | None = _GAIN
    kd_a_per_rad_s2: float | None = _GAIN
    kd_filter_hz: float | None = _GAIN
    kb_a_per_rad_s: float | None = _GAIN
    ka_a_per_rad_s2: float | None = _GAIN
    current_filter_1_hz: float | None = _GAIN
    current_filter_2_hz: float | None = _GAIN
    current_filter_3_hz: float | None = _GAIN
    speed_filter_s: float | None = _GAIN
    inertia_setting_kgm2: float | None = _GAIN

    def values(self) -> dict[str, float]:
        return {key: value for key, value in self.model_dump().items() if value is not None}


class SpeedLoopWrite(BaseModel):
    before: SpeedLoopModel
    after: SpeedLoopModel
    written: list[list[Any]] = Field(description="[semantic name, raw value] in the order written")
