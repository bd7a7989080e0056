"""The response of a drive whose control cycle free-runs (the encoTRive: no 0x1006), in TIME rather than in samples
(docs/frequency-response.md §8, "A drive whose cycle free-runs").

Such a drive takes each SYNC when it arrives, so the answers are samples at the instants the host's SYNC producer
happened to reach the bus (σ 0.3 ms on a loaded host), not on a uniform grid.  Two things make that measurable:

- **The excitation is periodic in time**: the value sent before a SYNC is the multi-sine at the drive's present
  instant (``Excitation``), not entry k of a sequence, so its lines stay the harmonics of the period in seconds.
- **Each answer is placed at its own instant**: the frames' time stamps (the CAN adapter's; the simulator's virtual
  instants), less the frame's own time on the wire, are the SYNC's; the drive's values are those of its last
  control period before it.  The lines are then Hann-windowed Fourier integrals over two periods, hop one period,
  of signals that are exact between the instants: the target velocity the drive held from one SYNC to the next (a
  staircase), the shaft speed as the mean speed of each interval (the position increments, divided by the known
  gain of that mean-and-hold, which has no phase), and the current monitor's values on its own 1-ms grid.  The
  window lets a SYNC held back (a host stall) cost a little leakage instead of a wrong line.

Through the reference (the read-back target) the plant is the speed over the current, as in ``estimate``; the
closed loop is H1 from the staircase to the speed.  The noise left is the drive's own (the encoTRive's 4096-count
encoder): it takes ``WINDOWS`` windows to average to within about 1 dB and 10° (measured, §8).
"""

from __future__ import annotations

import bisect
import cmath
import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from servostudio.services.frequency import estimate
from servostudio.services.frequency.excitation import Multisine

#: windows averaged (two periods each, one apart): the free-running encoTRive's noise needs this many for ≈ 1 dB
WINDOWS = 24
#: a window in which two answers are further apart than this is not used: a SYNC held back that long (a stalled host)
#: leaves a step in the excitation and its transient in the response (measured: runs with 12–66 ms gaps came out
#: 4–16 dB off, runs with gaps of at most 6.5 ms within 1.5 dB to 200 Hz)
MAX_GAP_S = 0.01
#: at most this many times the answers the windows take are waited for windows without a stall
MORE_WINDOWS = 1.5
#: table points per sample of the excitation evaluated in time (linear interpolation: < 2 % off at 400 Hz)
FINE = 16


class Excitation:
    """The multi-sine as a function of time (peak 1), periodic in ``signal.period_s``: its lines from the designed
    samples, tabulated ``FINE`` times per sample."""

    def __init__(self, signal: Multisine) -> None:
        count, period = signal.samples * FINE, signal.period_s
        lines = [(2.0 * math.pi * h / count, _line(signal.values, h)) for h in signal.harmonics]
        self.period = period
        self.table = [sum((c * cmath.exp(1j * w * i)).real for w, c in lines) for i in range(count)]

    def at(self, seconds: float) -> float:
        count = len(self.table)
        x = seconds / self.period % 1.0 * count
        i = int(x)
        share = x - i
        return self.table[i % count] * (1.0 - share) + self.table[(i + 1) % count] * share


def _line(values: Sequence[float], harmonic: int) -> complex:
    """The complex amplitude of one line of a periodic sequence: x(t) = Re(c·e^{jωt})."""
    n = len(values)
    return 2.0 / n * sum(v * cmath.exp(-2j * math.pi * harmonic * i / n) for i, v in enumerate(values))


@dataclass
class DriveClock:
    """The drive's time (its answers' stamps) from the host's monotonic clock: the smallest delay from a stamp to
    its arrival here over the last ``RENEW`` answers (so a drive clock that drifts against the host's is followed)."""

    RENEW = 1024
    lag: float | None = None
    seen: int = 0
    fresh: float = math.inf

    def answered(self, stamp: float, arrived: float) -> None:
        delay = arrived - stamp
        self.seen += 1
        self.fresh = min(self.fresh, delay)
        self.lag = delay if self.lag is None else min(self.lag, delay)
        if self.seen % self.RENEW == 0:
            self.lag, self.fresh = self.fresh, math.inf

    def now(self) -> float | None:
        return None if self.lag is None else time.monotonic() - self.lag


def ticks(stamps: Sequence[float], control_period_s: float) -> list[int]:
    """The drive's last control period before each SYNC: its values are that period's."""
    return [math.floor(stamp / control_period_s + 1e-9) for stamp in stamps]


def _exp_integral(nu: float, low: float, high: float) -> complex:
    """∫ e^{−jνt} dt from ``low`` to ``high``."""
    if abs(nu) < 1e-12:
        return complex(high - low)
    return (cmath.exp(-1j * nu * high) - cmath.exp(-1j * nu * low)) / (-1j * nu)


def _span(instants: Sequence[float], start: float, length: float) -> range:
    """The intervals [instants[k], instants[k+1]) that reach into the window."""
    first = max(bisect.bisect_right(instants, start) - 1, 0)
    return range(first, min(bisect.bisect_left(instants, start + length), len(instants) - 1))


def staircase_line(instants: Sequence[float], held: Sequence[float], omega: float, start: float,
                   length: float) -> complex:  # fmt: skip
    """The line at ``omega`` of the staircase ``held[k]`` from ``instants[k]`` to the next instant, Hann-windowed over
    [start, start + length): exact (the window times e^{−jωt} is three exponentials)."""
    step = 2.0 * math.pi / length
    below, above = 0.5 * cmath.exp(-1j * step * start), 0.5 * cmath.exp(1j * step * start)
    total = 0j
    for k in _span(instants, start, length):
        low, high = max(instants[k], start), min(instants[k + 1], start + length)
        if high > low:
            part = _exp_integral(omega, low, high) - below * _exp_integral(omega - step, low, high)
            total += held[k] * (part - above * _exp_integral(omega + step, low, high))
    return 2.0 * total / length


def speed_line(instants: Sequence[float], positions: Sequence[float], omega: float, start: float,
               length: float) -> complex:  # fmt: skip
    """The shaft speed's line from the position increments: each interval's mean speed (exact) held over it, divided
    by that mean-and-hold's gain at ``omega``, Σ w·Δ·sinc²(ωΔ/2) / Σ w·Δ (real: the mean is centred, no phase)."""
    means, gain, weight = [], 0.0, 0.0
    for k in range(len(positions) - 1):
        width = instants[k + 1] - instants[k]
        means.append((positions[k + 1] - positions[k]) / width if width > 0 else 0.0)
        centre = 0.5 * (instants[k] + instants[k + 1])
        if width > 0 and start <= centre < start + length:
            w = 1.0 - math.cos(2.0 * math.pi * (centre - start) / length)
            half = 0.5 * omega * width
            gain += w * width * (math.sin(half) / half) ** 2
            weight += w * width
    return staircase_line(instants, [*means, 0.0], omega, start, length) * weight / gain


def grid_line(times: Sequence[float], values: Sequence[float], omega: float, start: float, length: float,
              spacing: float) -> complex:  # fmt: skip
    """The line of point samples on a uniform grid (the current monitor's), Hann-windowed: a DFT, exact for lines
    below half the grid's rate."""
    total = 0j
    for i in range(bisect.bisect_left(times, start), bisect.bisect_left(times, start + length)):
        t = times[i]
        total += (1.0 - math.cos(2.0 * math.pi * (t - start) / length)) * values[i] * cmath.exp(-1j * omega * t)
    return 2.0 * total * spacing / length


def refresh_phase(periods: Sequence[int], values: Sequence[float], hold: int) -> int:
    """Which control periods, modulo ``hold``, a monitored value is refreshed in: the phase at which samples in the
    same refresh interval agree and samples in different ones differ most often."""

    def score(phase: int) -> int:
        groups = [(n - phase) // hold for n in periods]
        pairs = zip(groups, groups[1:], values, values[1:], strict=False)
        return sum((g == h) == (u == v) for g, h, u, v in pairs)

    return max(range(hold), key=score)


def monitored(periods: Sequence[int], values: Sequence[float], hold: int, control_period_s: float,
              latency_s: float) -> tuple[list[float], list[float]]:  # fmt: skip
    """A value the drive refreshes every ``hold`` control periods (0x6078) on its own uniform grid: each refresh's
    value at the instant it was measured (``latency_s`` before the refresh), a refresh no SYNC saw interpolated."""
    phase = refresh_phase(periods, values, hold)
    seen: dict[int, float] = {}
    for n, value in zip(periods, values, strict=True):
        seen.setdefault((n - phase) // hold, value)
    known = sorted(seen)
    times, grid = [], []
    for group in range(known[0], known[-1] + 1):
        if group not in seen:
            at = bisect.bisect_left(known, group)
            low, high = known[at - 1], known[at]
            seen[group] = seen[low] + (seen[high] - seen[low]) * (group - low) / (high - low)
        times.append((group * hold + phase) * control_period_s - latency_s)
        grid.append(seen[group])
    return times, grid


@dataclass(frozen=True)
class Timed:
    """The response placed in time: each answer's instant and values in SI units."""

    instants: list[float]
    positions: list[float]  # rad
    targets: list[float]  # rad/s, held from its instant to the next
    current: tuple[list[float], list[float]] | None  # (instants, N·m or A) on the monitor's grid


def clean_windows(instants: Sequence[float], period_s: float, wanted: int, last: bool) -> list[float] | None:
    """The starts of ``wanted`` windows (two periods, one period apart, from the first answer on): the first ones in
    which no two answers are more than ``MAX_GAP_S`` apart; on the ``last`` call (the time allowed is up) the ones
    with the smallest gaps, which their coherence then shows; None while the answers do not hold enough."""
    gaps: list[float] = []
    start = instants[0]
    while start + 2.0 * period_s <= instants[-1]:
        inside = range(bisect.bisect_left(instants, start), bisect.bisect_left(instants, start + 2.0 * period_s))
        gaps.append(max(instants[i + 1] - instants[i] for i in inside))
        start += period_s
    clean = [k for k, gap in enumerate(gaps) if gap <= MAX_GAP_S]
    if len(clean) < wanted and (not last or len(gaps) < wanted):
        return None
    chosen = clean[:wanted] if len(clean) >= wanted else sorted(sorted(range(len(gaps)), key=gaps.__getitem__)[:wanted])
    return [instants[0] + k * period_s for k in chosen]


def lines_of(response: Timed, signal: Multisine, starts: Sequence[float]) -> tuple[list[estimate.Lines], ...]:
    """(reference, input, output) lines per window of two periods starting at ``starts``."""
    omegas = [2.0 * math.pi * f for f in signal.frequencies_hz]
    length = 2.0 * signal.period_s
    reference, inputs, outputs = [], [], []
    for start in starts:
        reference.append([staircase_line(response.instants, response.targets, w, start, length) for w in omegas])
        outputs.append([speed_line(response.instants, response.positions, w, start, length) for w in omegas])
        if response.current is not None:
            times, values = response.current
            spacing = times[1] - times[0]
            inputs.append([grid_line(times, values, w, start, length, spacing) for w in omegas])
    return reference, inputs, outputs


def estimate_timed(loop: str, response: Timed, signal: Multisine, starts: Sequence[float]) -> list[estimate.Point]:
    """Closed loop: H1 from the staircase the drive held to the shaft speed; plant: the speed over the current,
    through the target read back (the reference)."""
    reference, inputs, outputs = lines_of(response, signal, starts)
    if loop == "closed":
        return estimate.h1(reference, outputs, signal.frequencies_hz)
    return estimate.by_reference(reference, inputs, outputs, signal.frequencies_hz)


def in_time(excitation: Excitation, clock: Callable[[], float | None], fallback_s: float) -> Callable[[int], float]:
    """Sample k: the excitation at the drive's present instant (before the first answer: at k·``fallback_s``)."""

    def value(k: int) -> float:
        now = clock()
        return excitation.at(k * fallback_s if now is None else now)

    return value
