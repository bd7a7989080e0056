"""What a recorded step response says about a loop: rise time, overshoot, settling time, and the −3 dB bandwidth
measured from the recording itself (not computed from the tuning formula).

The bandwidth is the closed loop's frequency response estimated from the step: H(f) = DFT(Δy) / DFT(Δr), the
transforms of the sample-to-sample changes of the response y and of the reference r (a step's change is one
impulse, so any reference shape works). The first-order filters of the measurement itself (the drive's speed
monitor, the speed loop's own measurement filter) are taken out: H_loop = H_measured · Π (1 + j·f/f_filter). The
bandwidth is the first frequency where |H_loop| falls below 1/√2. The transforms run from the recording's start
to a few settling times past the step (``window``). Several recorded steps of the same loop give one estimate from
the mean of their H(f) (``mean_bandwidth``): each step's quantisation noise is its own, the loop is the same.
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


#: one recording: sample times (s), reference, response
Recording = tuple[Sequence[float], Sequence[float], Sequence[float]]


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
    shaped = _shaped(times, reference, response)
    if shaped is None:
        return StepMetrics(None, None, None, None)
    moments, shape = shaped
    settling = _settling_time(moments, shape)
    windowed = window(times, reference, response)
    return StepMetrics(
        _rise_time(moments, shape),
        round(max(0.0, max(shape) - 1.0) * 100.0, 2),
        settling,
        mean_bandwidth([windowed], filters_hz) if windowed is not None else None,
    )


def _shaped(
    times: Sequence[float], reference: Sequence[float], response: Sequence[float]
) -> tuple[list[float], list[float]] | None:
    """The response from the step on, normalised to 0 before and 1 at the final reference, with its moments."""
    start = _step_index(reference)
    if start is None:
        return None
    before, after = _mean(response[: max(start, 1)]), reference[-1]
    height = after - before
    if height == 0:
        return None
    shape = [(value - before) / height for value in response[start:]]
    return [time - times[start] for time in times[start:]], shape


def window(times: Sequence[float], reference: Sequence[float], response: Sequence[float]) -> Recording | None:
    """The samples the bandwidth is estimated from: the response's own motion, up to a few settling times past the
    step. The settled tail adds only the speed measurement's quantisation noise to the transforms (it bends the
    estimated |H| by tens of per cent on a small step), and next to no signal. None: no step in the recording."""
    shaped = _shaped(times, reference, response)
    if shaped is None:
        return None
    start = _step_index(reference) or 0
    settling = _settling_time(*shaped)
    end = len(times)
    if settling is not None:
        until = times[start] + max(WINDOW_SETTLING_TIMES * settling, WINDOW_MIN_S)
        end = next((n for n in range(start, len(times)) if times[n] > until), len(times))
    return times[:end], reference[:end], response[:end]


def mean_bandwidth(recordings: Sequence[Recording], filters_hz: Sequence[float] = ()) -> float | None:
    """The −3 dB frequency of the mean frequency response of several recorded steps of one loop (rising or falling:
    each H is a ratio, its sign cancels)."""
    if not recordings:
        return None
    nyquist = min(_nyquist(times) for times, _, _ in recordings)
    previous = (0.0, 1.0)
    frequency = SCAN_STEP_HZ
    while frequency <= min(SCAN_UP_TO_HZ, nyquist):
        ratios = [_ratio(frequency, recording) for recording in recordings]
        if any(ratio is None for ratio in ratios):
            return None
        gain = abs(sum(ratio for ratio in ratios if ratio is not None) / len(ratios) * _filters(frequency, filters_hz))
        if gain < HALF_POWER:
            low, low_gain = previous
            share = (low_gain - HALF_POWER) / (low_gain - gain) if low_gain != gain else 0.0
            return round(low + share * (frequency - low), 1)
        previous = (frequency, gain)
        frequency += SCAN_STEP_HZ
    return None


def _nyquist(times: Sequence[float]) -> float:
    return 0.5 / (times[1] - times[0]) if len(times) > 1 and times[1] > times[0] else 0.0


def _filters(frequency: float, filters_hz: Sequence[float]) -> complex:
    """What takes the measurement filters out: Π (1 + j·f/f_filter)."""
    product = complex(1.0)
    for filter_hz in filters_hz:
        product *= 1 + 1j * frequency / filter_hz
    return product


def _ratio(frequency: float, recording: Recording) -> complex | None:
    """DFT(Δy) / DFT(Δr) of one recording at one frequency (None: the reference has no change there)."""
    times, reference, response = recording
    dr = [b - a for a, b in itertools.pairwise(reference)]
    dy = [b - a for a, b in itertools.pairwise(response)]
    turns = [cmath.exp(-2j * math.pi * frequency * moment) for moment in times[1:]]
    into = sum(change * turn for change, turn in zip(dr, turns, strict=True))
    out = sum(change * turn for change, turn in zip(dy, turns, strict=True))
    return out / into if abs(into) != 0 else None


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
