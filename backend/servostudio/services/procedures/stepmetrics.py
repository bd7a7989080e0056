"""What a recorded step response says about a loop: rise time, overshoot, settling time, and the −3 dB bandwidth
measured from the recording itself (not computed from the tuning formula).

The bandwidth is the closed loop's frequency response estimated from the step: H(f) = DFT(Δy) / DFT(Δr), the
transforms of the sample-to-sample changes of the response y and of the reference r (a step's change is one
impulse, so any reference shape works). The first-order filters of the measurement itself (the drive's speed
monitor, the speed loop's own measurement filter) are taken out: H_loop = H_measured · Π (1 + j·f/f_filter). The
bandwidth is the first frequency where |H_loop| falls below 1/√2. The transforms run from the recording's start
to a few settling times past the step (``_window_end``).
"""

from __future__ import annotations

import cmath
import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass

#: the band around the final value a settled response stays in
SETTLING_BAND = 0.05
HALF_POWER = 1.0 / math.sqrt(2.0)
#: frequencies scanned for the bandwidth, Hz
SCAN_STEP_HZ = 2.0
SCAN_UP_TO_HZ = 600.0
#: the bandwidth's samples: this many settling times past the step, and at least WINDOW_MIN_S
WINDOW_SETTLING_TIMES = 2.0
WINDOW_MIN_S = 0.02


@dataclass(frozen=True)
class StepMetrics:
    rise_time_s: float | None
    overshoot_pct: float | None
    settling_time_s: float | None
    bandwidth_hz: float | None

    def as_dict(self) -> dict[str, float | None]:
        return {
            "rise_time_s": self.rise_time_s,
            "overshoot_pct": self.overshoot_pct,
            "settling_time_s": self.settling_time_s,
            "bandwidth_hz": self.bandwidth_hz,
        }


def step_metrics(
    times: Sequence[float], reference: Sequence[float], response: Sequence[float], filters_hz: Sequence[float] = ()
) -> StepMetrics:
    """The metrics of one step (``reference`` jumps once); None where the recording does not tell."""
    start = _step_index(reference)
    if start is None:
        return StepMetrics(None, None, None, None)
    before, after = _mean(response[: max(start, 1)]), reference[-1]
    height = after - before
    if height == 0:
        return StepMetrics(None, None, None, None)
    shape = [(value - before) / height for value in response[start:]]
    moments = [time - times[start] for time in times[start:]]
    settling = _settling_time(moments, shape)
    end = _window_end(times, start, settling)
    return StepMetrics(
        _rise_time(moments, shape),
        round(max(0.0, max(shape) - 1.0) * 100.0, 2),
        settling,
        bandwidth(times[:end], reference[:end], response[:end], filters_hz),
    )


def _window_end(times: Sequence[float], start: int, settling: float | None) -> int:
    """The end of the samples the bandwidth is estimated from: the response's own motion, up to a few settling
    times past the step. The settled tail adds only the speed measurement's quantisation noise to the transforms
    (it bends the estimated |H| by tens of per cent on a small step), and next to no signal."""
    if settling is None:
        return len(times)
    until = times[start] + max(WINDOW_SETTLING_TIMES * settling, WINDOW_MIN_S)
    return next((n for n in range(start, len(times)) if times[n] > until), len(times))


def bandwidth(
    times: Sequence[float], reference: Sequence[float], response: Sequence[float], filters_hz: Sequence[float] = ()
) -> float | None:
    """The −3 dB frequency of the loop from its recorded step (None: not within the scanned range)."""
    dr = [b - a for a, b in itertools.pairwise(reference)]
    dy = [b - a for a, b in itertools.pairwise(response)]
    moments = times[1:]
    previous = (0.0, 1.0)
    frequency = SCAN_STEP_HZ
    nyquist = 0.5 / (times[1] - times[0]) if len(times) > 1 and times[1] > times[0] else 0.0
    while frequency <= min(SCAN_UP_TO_HZ, nyquist):
        gain = _gain(frequency, moments, dr, dy, filters_hz)
        if gain is None:
            return None
        if gain < HALF_POWER:
            low, low_gain = previous
            share = (low_gain - HALF_POWER) / (low_gain - gain) if low_gain != gain else 0.0
            return round(low + share * (frequency - low), 1)
        previous = (frequency, gain)
        frequency += SCAN_STEP_HZ
    return None


def _gain(frequency: float, moments: Sequence[float], dr: Sequence[float], dy: Sequence[float],
          filters_hz: Sequence[float]) -> float | None:  # fmt: skip
    turns = [cmath.exp(-2j * math.pi * frequency * moment) for moment in moments]
    into = sum(change * turn for change, turn in zip(dr, turns, strict=True))
    out = sum(change * turn for change, turn in zip(dy, turns, strict=True))
    if abs(into) == 0:
        return None
    ratio = out / into
    for filter_hz in filters_hz:
        ratio *= 1 + 1j * frequency / filter_hz
    return abs(ratio)


def _step_index(reference: Sequence[float]) -> int | None:
    """The first sample past half of the reference's change."""
    if len(reference) < 3 or reference[-1] == reference[0]:
        return None
    half = (reference[0] + reference[-1]) / 2
    rising = reference[-1] > reference[0]
    return next((n for n, value in enumerate(reference) if (value >= half) == rising), None)


def _rise_time(moments: Sequence[float], shape: Sequence[float]) -> float | None:
    low = next((t for t, value in zip(moments, shape, strict=True) if value >= 0.1), None)
    high = next((t for t, value in zip(moments, shape, strict=True) if value >= 0.9), None)
    return None if low is None or high is None else round(high - low, 6)


def _settling_time(moments: Sequence[float], shape: Sequence[float]) -> float | None:
    """When the response entered the band around its final value for good (None: it never did)."""
    outside = [n for n, value in enumerate(shape) if abs(value - 1.0) > SETTLING_BAND]
    if not outside:
        return 0.0
    last = outside[-1]
    return None if last >= len(shape) - 1 else round(moments[last + 1], 6)


def _mean(values: Sequence[float]) -> float:
    return sum(values) / len(values) if values else 0.0
