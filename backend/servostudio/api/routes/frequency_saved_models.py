"""Saved frequency responses as the REST API shows them (the result dict of docs/frequency-response.md, contract of
issue #16).  Names start with ``Saved``: the measurement's own models (``frequency_models.py``) are another file's."""

from __future__ import annotations

from typing import Any

from pydantic import BaseModel, ConfigDict, Field


class SavedFrequencyPoint(BaseModel):
    """One row of the pinned CSV; a value that is not a finite number there (``nan``: coherence not estimated) is
    null here, JSON having no NaN."""

    freq_hz: float | None
    magnitude_db: float | None = Field(description="plant: dB of (rad/s)/(N·m); closed loop: dB of actual/demanded")
    phase_deg: float | None
    coherence: float | None = Field(description="0..1")


class SavedFrequencyMarkers(BaseModel):
    """What the Bode page marks; null when the response has none (services/frequency/markers.py)."""

    model_config = ConfigDict(extra="allow")
    bandwidth_hz: float | None = None
    gain_margin_db: float | None = None
    phase_margin_deg: float | None = None
    resonance_hz: float | None = None
    antiresonance_hz: float | None = None


class SavedFrequencySummary(BaseModel):
    """A saved result without its points (``error``: a sidecar that cannot be read, naming its file)."""

    name: str
    kind: str | None = None
    loop: str | None = Field(default=None, description="plant | closed")
    node: int | None = None
    device: str | None = None
    axis: str | None = None
    time: str | None = Field(default=None, description="when it was measured, ISO-8601 UTC")
    user: str | None = None
    excitation: dict[str, Any] | None = None
    markers: SavedFrequencyMarkers | None = None
    aborted: str | None = None
    error: str | None = None


class SavedFrequencyResult(BaseModel):
    """A saved result with its points, as the measurement made it."""

    model_config = ConfigDict(extra="allow")
    name: str
    kind: str = "frequency_response"
    loop: str
    node: int | None = None
    device: str | None = None
    axis: str | None = None
    time: str | None = None
    user: str | None = None
    excitation: dict[str, Any] | None = None
    points: list[SavedFrequencyPoint]
    markers: SavedFrequencyMarkers | None = None
    plant_fit: dict[str, float] | None = Field(
        default=None, description="rigid fit of a plant measurement: inertia_kgm2, viscous_friction_nms_per_rad"
    )
    gains: dict[str, Any] | None = Field(
        default=None, description="the speed loop at measurement time (GET …/speed-loop)"
    )
    aborted: str | None = None
