"""The plant from a recorded experiment, by least squares (docs/identification.md § Estimator).

The rigid axis ``T = J·dω/dt + B·ω + Tc·sgn(ω) + Tl`` multiplied by dθ = ω·dt and summed over a segment of samples
is its energy balance:

    Σ T·dθ = J·½(ω₂² − ω₁²) + B·Σ ω·dθ + Tc·Σ |dθ| + Tl·Σ dθ

No time appears in it: only the position increments, the measured speed at the segment's ends and the torque at
each sample. A sample period that drifts (a SYNC late on a loaded host, a bus behind) changes nothing, and the speed
and current filters of the drive hardly do, because the segments end where the speed is steady. Each segment is one
row, divided by its travel Σ |dθ| (every row is a mean torque); the four unknowns are their least-squares solution.

The segments: the record is cut where the speed changes sign (a reversal keeps the kinetic energy, and Coulomb
friction changes sign there), and each hold (the longest run of samples within 5 % of a held speed) is cut in two — its
first third (the loop settling) belongs to the transition, the rest (less its last tenth, where the next ramp has
begun) is a steady row that measures the friction at that speed.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

from servostudio.errors import InvalidInput

#: a segment shorter than this (rad of travel) says nothing a longer one does not
MIN_TRAVEL_RAD = 0.05
#: a hold shorter than this many samples is not split into settling and steady parts, nor is a shorter segment a row
MIN_HOLD_SAMPLES = 8
#: a sample within this share of a held speed belongs to its hold
HOLD_BAND = 0.05
#: the first 1/SETTLING of a hold is the loop settling (a transition row), the rest up to its tail a steady row
SETTLING = 3
#: the steady row leaves out this fraction of the hold at its end: the ramp out of it has begun while the speed is
#: still within the band, and its torque is already the ramp's
TAIL = 10
#: rounds of the alternating fit (friction ↔ inertia); the third changes nothing visible
ALTERNATIONS = 4
#: samples either side of a segment's end its speed is averaged over
ENDPOINT = 4
#: the torque shifts tried, in samples
SHIFTS = (-2, -1, 0, 1, 2, 3)


class IdentificationFailed(InvalidInput):
    """The recording does not determine the plant (too few segments, no motion, a singular fit)."""


@dataclass(frozen=True)
class Record:
    """One experiment in SI units, sample by sample: shaft angle (rad), measured speed (rad/s) and motor torque (N·m);
    and the speeds the profile held (rad/s)."""

    position_rad: Sequence[float]
    speed_rad_s: Sequence[float]
    torque_nm: Sequence[float]
    levels_rad_s: Sequence[float]


@dataclass(frozen=True)
class Plant:
    inertia_kgm2: float
    viscous_friction_nms_per_rad: float
    coulomb_friction_nm: float
    load_torque_nm: float
    residual: float
    rows: int
    torque_shift_samples: int = 0

    def as_dict(self) -> dict[str, float]:
        return {
            "inertia_kgm2": _significant(self.inertia_kgm2),
            "viscous_friction_nms_per_rad": _significant(self.viscous_friction_nms_per_rad),
            "coulomb_friction_nm": _significant(self.coulomb_friction_nm),
            "load_torque_nm": _significant(self.load_torque_nm),
            "residual": round(self.residual, 4),
        }


def estimate(record: Record) -> Plant:
    """The plant of the torque shift that fits best (smallest residual): the drive measures its current through a
    filter and updates it on its own period, so the torque samples may lag the motion by a sample or two."""
    return _physical(best_fit(record), record)


def best_fit(record: Record) -> Plant:
    """The fit of the best torque shift, physical or not (a first pass wants only its inertia: the ramps give it
    well even when the holds are too rough for the friction)."""
    fits = [_fit(shifted(record, shift)) for shift in SHIFTS]
    best = min(range(len(fits)), key=lambda n: fits[n].residual)
    return replace(fits[best], torque_shift_samples=SHIFTS[best])


def _physical(plant: Plant, record: Record) -> Plant:
    """A fit that no mechanism has (no inertia, friction that drives the axis) is refused, never reported: it comes
    of a run the axis could not follow (a current limit below the ramps' torque) or a recording that misses them.
    Viscous friction may come out a little below zero on an axis that has almost none: down to 2 % of the Coulomb
    friction at the highest speed held."""
    top = max((abs(level) for level in record.levels_rad_s), default=0.0)
    faults = [
        f"inertia {plant.inertia_kgm2:.3g} kg·m²" if plant.inertia_kgm2 <= 0 else "",
        f"Coulomb friction {plant.coulomb_friction_nm:.3g} N·m" if plant.coulomb_friction_nm < 0 else "",
        f"viscous friction {plant.viscous_friction_nms_per_rad:.3g} N·m·s/rad"
        if plant.viscous_friction_nms_per_rad * top < -0.02 * abs(plant.coulomb_friction_nm) else "",
    ]  # fmt: skip
    found = [fault for fault in faults if fault]
    if found:
        raise IdentificationFailed(
            f"the fit is not physical ({', '.join(found)}): the axis probably did not follow the profile; raise the "
            "current limit or lower the acceleration"
        )
    return plant


def shifted(record: Record, shift: int) -> Record:
    """The record with each torque sample taken ``shift`` samples later (the ends repeated)."""
    torque = list(record.torque_nm)
    if shift > 0:
        torque = torque[shift:] + [torque[-1]] * shift
    elif shift < 0:
        torque = [torque[0]] * -shift + torque[:shift]
    return replace(record, torque_nm=torque)


def _fit(record: Record) -> Plant:
    """The least-squares plant of one recording: friction and load from the steady rows, the inertia from the
    transitions with that friction, alternated (a hold still settling carries a little acceleration)."""
    steady, moving = segments(record)
    friction_rows = [row for start, end in steady if (row := _row(record, start, end)) is not None]
    inertia_rows = [row for start, end in moving if (row := _row(record, start, end)) is not None]
    if len(friction_rows) < 3:
        raise IdentificationFailed(f"the recording has {len(friction_rows)} steady speed holds; the fit needs 3")
    if not inertia_rows:
        raise IdentificationFailed("the recording has no acceleration between its holds")
    solution = [0.0, 0.0, 0.0, 0.0]
    for _ in range(ALTERNATIONS):
        solution[1:] = solve([row[1:] for row, _ in friction_rows], _less(friction_rows, solution, 0))
        solution[0] = solve([row[:1] for row, _ in inertia_rows], _less(inertia_rows, solution, 1))[0]
    rows = friction_rows + inertia_rows
    inertia, viscous, coulomb, load = solution
    return Plant(inertia, viscous, coulomb, load, residual=_residual(rows, solution), rows=len(rows))


def _less(rows: Sequence[tuple[list[float], float]], solution: Sequence[float], keep: int) -> list[float]:
    """Each row's value less the part the other unknowns explain (``keep`` 0: all but the inertia; 1: the inertia
    only)."""
    if keep == 0:
        return [value - row[0] * solution[0] for row, value in rows]
    return [value - sum(a * x for a, x in zip(row[1:], solution[1:], strict=True)) for row, value in rows]


def segments(record: Record) -> tuple[list[tuple[int, int]], list[tuple[int, int]]]:
    """(steady, moving) segments as (first, last) sample: the second halves of the demand's holds, and the rest cut
    where the speed changes sign."""
    speed = record.speed_rad_s
    runs = [run for level in dict.fromkeys(record.levels_rad_s) if level for run in holds(speed, level)]
    steady = [(start + (end - start) // SETTLING, end - (end - start) // TAIL) for start, end in runs
              if end - start >= MIN_HOLD_SAMPLES]  # fmt: skip
    points = {0, len(speed) - 1} | {point for segment in steady for point in segment}
    points |= {n for n in range(1, len(speed)) if (speed[n] > 0) != (speed[n - 1] > 0)}
    moving = [pair for pair in itertools.pairwise(sorted(points)) if pair not in steady and _whole(record, *pair)]
    return steady, moving


def _whole(record: Record, start: int, end: int) -> bool:
    """A segment of enough samples that does not end where the recording stopped mid-motion (a capture shorter than
    the run: its last speed is no end of anything)."""
    if end - start < MIN_HOLD_SAMPLES:
        return False
    last = len(record.speed_rad_s) - 1
    return end < last or abs(record.speed_rad_s[last]) <= HOLD_BAND * max(map(abs, record.levels_rad_s), default=0)


def holds(speed: Sequence[float], level: float) -> list[tuple[int, int]]:
    """(first, last) sample of the runs of speeds within ``HOLD_BAND`` of ``level`` that last at least half as long as
    the longest (the ramps pass through other levels briefly; a hold is a long stay)."""
    runs, start = [], None
    for n, value in enumerate([*speed, math.nan]):
        inside = abs(value - level) <= HOLD_BAND * abs(level)
        if inside and start is None:
            start = n
        elif not inside and start is not None:
            runs.append((start, n - 1))
            start = None
    longest = max((end - first for first, end in runs), default=0)
    return [(first, end) for first, end in runs if end - first >= longest / 2]


def _row(record: Record, start: int, end: int) -> tuple[list[float], float] | None:
    """The energy balance of samples start..end, divided by its travel; None for a segment without travel."""
    position, speed, torque = record.position_rad, record.speed_rad_s, record.torque_nm
    work = viscous = travel = net = 0.0
    for n in range(start, end):
        step = position[n + 1] - position[n]
        work += 0.5 * (torque[n] + torque[n + 1]) * step
        viscous += 0.5 * (speed[n] + speed[n + 1]) * step
        travel += abs(step)
        net += step
    if travel < MIN_TRAVEL_RAD:
        return None
    kinetic = 0.5 * (_speed_at(speed, end, start, end) ** 2 - _speed_at(speed, start, start, end) ** 2)
    return [kinetic / travel, viscous / travel, 1.0, net / travel], work / travel


def _speed_at(speed: Sequence[float], n: int, first: int, last: int) -> float:
    """The speed at sample n, averaged over ``ENDPOINT`` samples either side within the segment: the drive's speed
    is a whole number of its units (1 rpm on the encoTRive), and the average of a ramp is its middle."""
    low, high = max(first, n - ENDPOINT), min(last, n + ENDPOINT)
    width = min(n - low, high - n)
    window = speed[n - width : n + width + 1]
    return sum(window) / len(window)


def solve(rows: Sequence[Sequence[float]], values: Sequence[float]) -> list[float]:
    """Least squares by the normal equations, each column scaled to unit size first so that inertia
    (10⁻⁴) and load torque (1) are solved with the same precision."""
    size = len(rows[0])
    scale = [math.sqrt(sum(row[k] ** 2 for row in rows)) or 1.0 for k in range(size)]
    scaled = [[row[k] / scale[k] for k in range(size)] for row in rows]
    normal = [[sum(row[i] * row[j] for row in scaled) for j in range(size)] for i in range(size)]
    right = [sum(row[i] * value for row, value in zip(scaled, values, strict=True)) for i in range(size)]
    return [value / scale[k] for k, value in enumerate(_gauss(normal, right))]


def _gauss(matrix: list[list[float]], right: list[float]) -> list[float]:
    """Gaussian elimination with partial pivoting; a (near-)singular system is a failed identification."""
    size = len(right)
    for column in range(size):
        pivot = max(range(column, size), key=lambda row: abs(matrix[row][column]))
        if abs(matrix[pivot][column]) < 1e-12:
            raise IdentificationFailed("the recording does not separate inertia, friction and load (singular fit)")
        matrix[column], matrix[pivot] = matrix[pivot], matrix[column]
        right[column], right[pivot] = right[pivot], right[column]
        for row in range(size):
            if row != column:
                factor = matrix[row][column] / matrix[column][column]
                matrix[row] = [a - factor * b for a, b in zip(matrix[row], matrix[column], strict=True)]
                right[row] -= factor * right[column]
    return [right[k] / matrix[k][k] for k in range(size)]


def _residual(rows: Sequence[tuple[list[float], float]], solution: Sequence[float]) -> float:
    """RMS misfit over RMS value of the rows' mean torques (0: a perfect fit)."""
    misfit = sum((sum(a * x for a, x in zip(row, solution, strict=True)) - value) ** 2 for row, value in rows)
    total = sum(value**2 for _, value in rows)
    return math.sqrt(misfit / total) if total > 0 else 0.0


def _significant(value: float, digits: int = 5) -> float:
    return float(f"{value:.{digits}g}")
