"""The estimator of a frequency response from recorded input and output (docs/frequency-response.md §2).

Both signals are cut into blocks of exactly one excitation period; each block's DFT is taken at the excited lines
only.  The response is the H1 estimate over the blocks, ``H = Σ Y·U* / Σ |U|²`` (U, Y: the input's and the output's
line of each block), and the coherence ``γ² = |Σ Y·U*|² / (Σ |U|² · Σ |Y|²)``: 1 when every period says the same,
lower when noise, a drive that did not follow the excitation or a stream that reached the drive late (its measured
input then differs from period to period) spoil it.  The input is what the drive recorded it used, never the
designed signal, so a late or lost excitation sample is in U as much as in Y.

A speed is taken from the recorded position: the DFT of the sample-to-sample differences is ``(e^{jθ} − 1)·X``
(θ = 2π·h/samples) for the periodic part of the position — a constant base speed only adds to the 0th line — so the
position's line is ``D / (e^{jθ} − 1)`` and the shaft speed's ``jω·X``, exact for a periodic position, with neither
the half-sample delay nor the sinc droop of a difference quotient.

The plant fit: ``1/H = B + jωJ`` for the rigid plant, so each point gives J = Im(1/H)/ω and B = Re(1/H); their
coherence-weighted means are the fit (``rigid_fit``).
"""

from __future__ import annotations

import cmath
import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass

Lines = list[complex]


@dataclass(frozen=True)
class Point:
    freq_hz: float
    value: complex
    coherence: float

    def as_dict(self, phase_deg: float) -> dict[str, float]:
        magnitude = abs(self.value)
        return {
            "freq_hz": round(self.freq_hz, 6),
            "magnitude_db": round(20.0 * math.log10(magnitude), 4) if magnitude > 0 else -400.0,
            "phase_deg": round(phase_deg, 3),
            "coherence": round(self.coherence, 4),
        }


def hann(block: int) -> list[float]:
    """The periodic Hann window, scaled to mean 1 (a line keeps its amplitude)."""
    return [1.0 - math.cos(2.0 * math.pi * i / block) for i in range(block)]


def block_lines(
    samples: Sequence[float], harmonics: Sequence[int], block: int, window: Sequence[float] | None = None
) -> list[Lines]:
    """The DFT of each whole block of ``block`` samples at the harmonics (bins) given, windowed when asked."""
    blocks = len(samples) // block
    return [_lines(_windowed(samples[b * block : (b + 1) * block], window), harmonics, block) for b in range(blocks)]


def position_lines(
    positions: Sequence[float], harmonics: Sequence[int], block: int, window: Sequence[float] | None = None
) -> list[Lines]:
    """The periodic position's lines per block, from the sample-to-sample differences (a base speed drops out)."""
    steps = [later - earlier for earlier, later in itertools.pairwise(positions)]
    blocks = len(steps) // block
    factors = [cmath.exp(2j * math.pi * harmonic / block) - 1.0 for harmonic in harmonics]
    differences = [
        _lines(_windowed(steps[b * block : (b + 1) * block], window), harmonics, block) for b in range(blocks)
    ]
    return [[line / factor for line, factor in zip(row, factors, strict=True)] for row in differences]


def held_lines(
    samples: Sequence[float], harmonics: Sequence[int], block: int, hold: int, window: Sequence[float] | None = None
) -> list[Lines]:
    """The lines of a signal the drive updates only every ``hold`` records (0x6078 every 1 ms, recorded every
    250 µs): only the records where it was taken count (the phase of its changes), each at its own instant, so
    the result is comparable with a line of ``block`` records (× ``hold``)."""
    phase = update_phase(samples, hold)
    blocks = len(samples) // block
    result = []
    for b in range(blocks):
        start = b * block
        weights = window if window is not None else [1.0] * block
        taken = [(i, samples[start + i] * weights[i]) for i in range((phase - start) % hold, block, hold)]
        row = []
        for harmonic in harmonics:
            turn = -2j * math.pi * harmonic / block
            row.append(hold * sum(value * cmath.exp(turn * i) for i, value in taken))
        result.append(row)
    return result


def update_phase(samples: Sequence[float], hold: int) -> int:
    """Where, modulo ``hold``, a held signal changes most often (the records it was taken in)."""
    counts = [0] * hold
    for i in range(1, len(samples)):
        if samples[i] != samples[i - 1]:
            counts[i % hold] += 1
    return max(range(hold), key=counts.__getitem__)


def monitored_lines(
    samples: Sequence[float], harmonics: Sequence[int], block: int, spacing: int, hold: int
) -> list[Lines]:
    """The lines of a signal the drive takes every ``hold`` control periods (0x6078: every 1 ms, the current of the
    period before), sampled every ``spacing = hold − 1`` periods (the 0.75-ms SYNC: 3 of 250 µs).  In every ``hold``
    samples one falls where no new value came (it repeats the one before): where it falls places the samples in
    the drive's update grid, and each sample that brought a new value is taken at the instant that value was
    measured — comparable with a line of ``block`` samples at the SYNC instants.  A signal that changes at every
    sample (a drive that takes it at the SYNC) is taken at the sample instants."""
    if hold != spacing + 1:
        raise ValueError(f"a sample every {spacing} periods of a value taken every {hold}: not the SYNC's pattern")
    changes = [0] * hold
    for i in range(1, len(samples)):
        changes[i % hold] += samples[i] != samples[i - 1]
    repeat = min(range(hold), key=changes.__getitem__)
    if 4 * changes[repeat] > max(changes):
        return block_lines(samples, harmonics, block)
    first = (hold - 1 - spacing * repeat) % hold  # sample 0's control period in the update grid
    rows = []
    for start in range(0, len(samples) // block * block, block):
        taken = [
            (spacing * (k - start) - (first + spacing * k) % hold - 1, samples[k])
            for k in range(start, start + block)
            if k % hold != repeat
        ]
        turns = [-2j * math.pi * harmonic / (spacing * block) for harmonic in harmonics]
        rows.append([hold / spacing * sum(value * cmath.exp(turn * t) for t, value in taken) for turn in turns])
    return rows


def speed_lines(positions: list[Lines], frequencies_hz: Sequence[float]) -> list[Lines]:
    """jω·X: the shaft speed's lines from the position's."""
    return [[2j * math.pi * f * x for x, f in zip(row, frequencies_hz, strict=True)] for row in positions]


def h1(inputs: list[Lines], outputs: list[Lines], frequencies_hz: Sequence[float]) -> list[Point]:
    """The H1 estimate and its coherence at each line, over the blocks both signals have."""
    count = min(len(inputs), len(outputs))
    points = []
    for n, frequency in enumerate(frequencies_hz):
        cross = sum(outputs[b][n] * inputs[b][n].conjugate() for b in range(count))
        power_in = sum(abs(inputs[b][n]) ** 2 for b in range(count))
        power_out = sum(abs(outputs[b][n]) ** 2 for b in range(count))
        value = cross / power_in if power_in > 0 else complex("nan")
        coherence = abs(cross) ** 2 / (power_in * power_out) if power_in > 0 and power_out > 0 else 0.0
        points.append(Point(frequency, value, min(coherence, 1.0)))
    return points


def by_reference(
    reference: list[Lines], inputs: list[Lines], outputs: list[Lines], frequencies_hz: Sequence[float]
) -> list[Point]:
    """The response of output to input through a reference that drives both (the excitation the drive applied):
    ``H = Σ Y·R* / Σ U·R*``.  What in U or Y is not caused by the reference (the loop's own current, the current
    monitor's sampling of a changing current, quantisation) averages out instead of biasing H as it does in H1's
    ``Σ |U|²``.  The coherence is that of the output with the reference."""
    count = min(len(reference), len(inputs), len(outputs))
    points = []
    for n, frequency in enumerate(frequencies_hz):
        out_cross = sum(outputs[b][n] * reference[b][n].conjugate() for b in range(count))
        in_cross = sum(inputs[b][n] * reference[b][n].conjugate() for b in range(count))
        power_ref = sum(abs(reference[b][n]) ** 2 for b in range(count))
        power_out = sum(abs(outputs[b][n]) ** 2 for b in range(count))
        value = out_cross / in_cross if in_cross != 0 else complex("nan")
        coherence = abs(out_cross) ** 2 / (power_ref * power_out) if power_ref > 0 and power_out > 0 else 0.0
        points.append(Point(frequency, value, min(coherence, 1.0)))
    return points


def unwrapped_phases(points: Sequence[Point]) -> list[float]:
    """Phases in degrees, unwrapped from the first point on (a plant's −90° goes on down, never jumps by 360°)."""
    phases: list[float] = []
    for point in points:
        phase = math.degrees(cmath.phase(point.value))
        if phases:
            phase += 360.0 * round((phases[-1] - phase) / 360.0)
        phases.append(phase)
    return phases


def as_points(points: Sequence[Point]) -> list[dict[str, float]]:
    return [point.as_dict(phase) for point, phase in zip(points, unwrapped_phases(points), strict=True)]


def rigid_fit(points: Sequence[Point]) -> dict[str, float] | None:
    """J and B of ``1/(J·s + B)`` fitted to the measured plant; None without a usable point.

    Each point gives ``Im(1/H)/ω = J`` and ``Re(1/H) = B``; both are averaged with the coherence as weight, J over
    relative errors (a point's phase and magnitude errors weigh the same at every frequency) and B over the lower
    half of the points, where B·ω is not dwarfed by J·ω²."""
    usable = [point for point in points if abs(point.value) > 0 and point.coherence > 0]
    if not usable:
        return None
    inverse = [(1.0 / point.value, 2.0 * math.pi * point.freq_hz, point.coherence) for point in usable]
    inertia = sum(w * z.imag / omega for z, omega, w in inverse) / sum(w for _, _, w in inverse)
    low = inverse[: max(1, len(inverse) // 2)]
    friction = sum(w * z.real for z, _, w in low) / sum(w for _, _, w in low)
    return {"inertia_kgm2": inertia, "viscous_friction_nms_per_rad": max(friction, 0.0)}


def _windowed(samples: Sequence[float], window: Sequence[float] | None) -> Sequence[float]:
    return samples if window is None else [value * weight for value, weight in zip(samples, window, strict=True)]


def _lines(samples: Sequence[float], harmonics: Sequence[int], block: int) -> Lines:
    """Σ x_i·e^{−j2π·h·i/block} for each harmonic h (a rotating phasor: no trigonometry per sample)."""
    result = []
    for harmonic in harmonics:
        step = cmath.exp(-2j * math.pi * harmonic / block)
        phasor = 1.0 + 0j
        total = 0j
        for value in samples:
            total += value * phasor
            phasor *= step
        result.append(total)
    return result
