"""The frequency-response measurement's REST contract (issue #16, /work contract "FR"): the start request; the job's
result is the result dict (docs/frequency-response.md), as the saved results show it (``frequency_saved_models``)."""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field

from servostudio.services.frequency.measure import MeasureRequest
from servostudio.services.frequency.service import FrequencyRequest

ProjectName = Annotated[str, Field(min_length=1, max_length=120)]


class FrequencyStart(BaseModel):
    """Measure the plant (torque offset → shaft speed, in (rad/s)/(N·m)) or the closed speed loop (target → shaft
    speed) with a multi-sine; the axis runs at the base speed, within the position window and the current limit."""

    model_config = ConfigDict(
        extra="forbid",
        json_schema_extra={"examples": [{"loop": "plant", "from_hz": 5, "to_hz": 400, "points": 60}]},
    )
    loop: Literal["plant", "closed"] = "plant"
    from_hz: float = Field(5.0, ge=2.5, le=1000.0)
    to_hz: float = Field(400.0, gt=0.0, le=1000.0)
    points: int = Field(60, ge=2, le=400)
    amplitude_pct: float | None = Field(
        None,
        gt=0.0,
        le=100.0,
        description="plant: peak torque offset in % of the rated current (default 50); closed: peak speed "
        "excursion in % of the base speed (default 40)",
    )
    base_speed_rad_s: float = Field(10.0, gt=0.0, le=1000.0, description="the axis never crosses zero speed")
    position_window: float = Field(10.0, gt=0.0, le=10000.0, description="revolutions the axis may travel")
    current_limit_a: float | None = Field(None, gt=0.0, le=1000.0, description="above it: quick stop, aborted")
    periods: int = Field(4, ge=2, le=32, description="excitation periods averaged")
    project: ProjectName | None = Field(None, description="save the result under this project's axis")
    axis: ProjectName | None = None

    def request(self) -> FrequencyRequest:
        measure = MeasureRequest(
            loop=self.loop,
            from_hz=self.from_hz,
            to_hz=self.to_hz,
            points=self.points,
            amplitude_pct=self.amplitude_pct,
            base_speed_rad_s=self.base_speed_rad_s,
            position_window=self.position_window,
            current_limit_a=self.current_limit_a,
            periods=self.periods,
        )
        return FrequencyRequest(measure, self.project, self.axis)
