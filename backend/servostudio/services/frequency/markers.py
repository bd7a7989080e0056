"""What a frequency response is marked with, by the definitions the Bode page uses (frontend/src/lib/whatif/
markers.ts, docs/what-if.md § Markers), so a saved result and the page agree:

- bandwidth: the first frequency where the closed loop's magnitude falls below 1/√2 (−3.01 dB);
- phase margin 180° + ∠L at |L| = 1, gain margin −20·log|L| at ∠L = −180° (phase unwrapped), of the open loop L;
- resonance / anti-resonance: the strongest peak / dip, at least 3 dB prominent, of the plant's magnitude
  + 20·log10 f (flat for a rigid plant); the anti-resonance only below the resonance (measured on the motor, a
  two-mass plant's zero pair lies below its pole pair), so a lone dip is never one;
- crossings interpolated linearly in dB or degrees over log-frequency;
- only coherent points count (γ² ≥ ``MIN_COHERENCE``, docs/frequency-response.md §6): the others are dropped before
  anything is marked, so they neither make nor move a marker, a peak stands out of its coherent neighbours, and a
  marker with no coherent points to stand on is None.

A closed-loop measurement gives the bandwidth, and the margins of ``L = T / (1 − T)`` (T the measured closed loop:
exact for a loop whose reference and feedback pass the same controller, i.e. KCv = KDv = 0 and the speed filter
counted in the loop; its phase is taken on the branch where it lies in (−360°, 0°] at the gain crossover, since at
low frequency, where T ≈ 1, noise picks the branch); a plant measurement gives the resonances.
"""

from __future__ import annotations

import cmath
import math
from collections.abc import Mapping, Sequence

HALF_POWER_DB = -10.0 * math.log10(2.0)
PROMINENCE_DB = 3.0
#: at or above the 95 % noise floor of γ² for every allowed number of periods (2 … 32), and a point's random magnitude
#: error then ≤ 0.7 dB at 4 periods (docs/frequency-response.md §6)
MIN_COHERENCE = 0.95
#: an anti-resonance is where the shaft hardly moves: its dip has a small output and, by nature, a lower γ² (0.92 at
#: rest, less on a loaded host, for 0.99 beside it); 0.8 is still above the 95 % noise floor for 4 periods (0.63)
MIN_DIP_COHERENCE = 0.8
Points = Sequence[Mapping[str, float]]
FIELDS = ("freq_hz", "magnitude_db", "phase_deg")


def crossing_down(freq: Sequence[float], values: Sequence[float], level: float) -> float | None:
    """The log-frequency where ``values`` first crosses ``level`` going down; None when it never does."""
    for n in range(1, len(freq)):
        if values[n - 1] >= level > values[n]:
            share = (values[n - 1] - level) / (values[n - 1] - values[n])
            low, high = math.log10(freq[n - 1]), math.log10(freq[n])
            return float(10 ** (low + share * (high - low)))
    return None


def interpolate(freq: Sequence[float], values: Sequence[float], at: float) -> float:
    for n in range(1, len(freq)):
        if freq[n] >= at:
            low, high = math.log10(freq[n - 1]), math.log10(freq[n])
            share = (math.log10(at) - low) / (high - low)
            return values[n - 1] + share * (values[n] - values[n - 1])
    return values[-1]


def bandwidth(freq: Sequence[float], closed_db: Sequence[float]) -> float | None:
    return crossing_down(freq, closed_db, HALF_POWER_DB)


def margins(
    freq: Sequence[float], open_db: Sequence[float], open_phase_deg: Sequence[float]
) -> dict[str, float | None]:
    """Phase margin at the gain crossover, gain margin at the phase crossover (the phase unwrapped)."""
    crossover = crossing_down(freq, open_db, 0.0)
    phase_crossover = crossing_down(freq, open_phase_deg, -180.0)
    return {
        "gain_margin_db": None if phase_crossover is None else -interpolate(freq, open_db, phase_crossover),
        "phase_margin_deg": None if crossover is None else 180.0 + interpolate(freq, open_phase_deg, crossover),
    }


def resonances(freq: Sequence[float], plant_db: Sequence[float]) -> dict[str, float | None]:
    detrended = [value + 20.0 * math.log10(f) for f, value in zip(freq, plant_db, strict=True)]
    return {"resonance_hz": _extremum(freq, detrended, 1.0), "antiresonance_hz": _extremum(freq, detrended, -1.0)}


def markers_of(loop: str, points: Points) -> dict[str, float | None]:
    """Every marker a measurement of ``loop`` (plant or closed) gives; the others are None."""
    result: dict[str, float | None] = dict.fromkeys(
        ("bandwidth_hz", "gain_margin_db", "phase_margin_deg", "resonance_hz", "antiresonance_hz")
    )
    usable = coherent(points)
    if len(usable) < 2:
        return result
    freq = [point["freq_hz"] for point in usable]
    if loop == "plant":
        result["resonance_hz"] = resonances(freq, [point["magnitude_db"] for point in usable])["resonance_hz"]
        result["antiresonance_hz"] = _antiresonance(points, result["resonance_hz"])
        return result
    result["bandwidth_hz"] = bandwidth(freq, [point["magnitude_db"] for point in usable])
    open_db, open_phase = _open_loop(usable)
    result.update(margins(freq, open_db, _branch(freq, open_db, open_phase)))
    return result


def _antiresonance(points: Points, resonance_hz: float | None) -> float | None:
    """The strongest dip below the resonance, on points γ² ≥ ``MIN_DIP_COHERENCE``: without a resonance there is no
    anti-resonance (a dip the noise of a loaded host digs among a rigid plant's top points, γ² 0.84–0.96, is none)."""
    if resonance_hz is None:
        return None
    below = [point for point in coherent(points, MIN_DIP_COHERENCE) if point["freq_hz"] < resonance_hz]
    freq, plant_db = [point["freq_hz"] for point in below], [point["magnitude_db"] for point in below]
    return resonances(freq, plant_db)["antiresonance_hz"]


def coherent(points: Points, threshold: float = MIN_COHERENCE) -> list[Mapping[str, float]]:
    """The points a marker may stand on: finite, at a positive frequency, γ² ≥ ``threshold`` (a coherence that is
    missing or not finite — not estimated — supports nothing)."""
    return [point for point in points
            if _finite(point) and point["freq_hz"] > 0 and _coherent(point.get("coherence"), threshold)]  # fmt: skip


def _finite(point: Mapping[str, float]) -> bool:
    return all(isinstance(point.get(key), int | float) and math.isfinite(point[key]) for key in FIELDS)


def _coherent(coherence: float | None, threshold: float) -> bool:
    return isinstance(coherence, int | float) and math.isfinite(coherence) and coherence >= threshold


def _branch(freq: Sequence[float], open_db: Sequence[float], phases: list[float]) -> list[float]:
    """The unwrapped phase moved by whole turns so that it lies in (−360°, 0°] at the gain crossover: a measured
    L = T/(1 − T) starts near ±180° at low frequency (T ≈ 1), where noise picks the branch."""
    crossover = crossing_down(freq, open_db, 0.0)
    if crossover is None:
        return phases
    turns = math.floor(interpolate(freq, phases, crossover) / 360.0)
    return [phase - 360.0 * (turns + 1) for phase in phases]


def _open_loop(points: Points) -> tuple[list[float], list[float]]:
    """|L| in dB and ∠L unwrapped, L = T / (1 − T)."""
    magnitudes: list[float] = []
    phases: list[float] = []
    for point in points:
        closed = 10 ** (point["magnitude_db"] / 20.0) * cmath.exp(1j * math.radians(point["phase_deg"]))
        loop = closed / (1.0 - closed) if closed != 1 else complex(1e12)
        magnitudes.append(20.0 * math.log10(max(abs(loop), 1e-300)))
        phase = math.degrees(cmath.phase(loop))
        if phases:
            phase += 360.0 * round((phases[-1] - phase) / 360.0)
        phases.append(phase)
    return magnitudes, phases


def _extremum(freq: Sequence[float], values: Sequence[float], sign: float) -> float | None:
    """The strongest local peak (sign +1) or dip (−1) standing out by ``PROMINENCE_DB`` from both sides."""
    best, best_height = None, PROMINENCE_DB
    for n in range(1, len(values) - 1):
        v = sign * values[n]
        if v < sign * values[n - 1] or v < sign * values[n + 1]:
            continue
        left = min(sign * x for x in values[:n])
        right = min(sign * x for x in values[n + 1 :])
        height = v - max(left, right)
        if height >= best_height:
            best, best_height = freq[n], height
    return best
