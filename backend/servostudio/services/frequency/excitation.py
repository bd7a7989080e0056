"""The excitation of a frequency-response measurement: one period of a multi-sine, sampled at the SYNC rate.

Why a multi-sine (docs/frequency-response.md §1): every frequency is excited at once (a swept sine needs one settling
per point), the signal is exactly periodic — its lines are whole multiples of ``1 / period``, so a window of whole
periods has no leakage and periods can be averaged —, and Schroeder's phases ``φ_k = −π·k·(k − 1)/N`` keep its crest
factor low, then a few rounds of clipping (Van der Ouderaa, Schoukens and Renneboog, 1988: clip the peaks, keep the
lines' phases, restore their amplitudes) lower it further, so the amplitude a drive may take buys the most
excitation per line.  A PRBS spreads its power over every bin (most of it where nothing is measured) and a chirp is
not periodic in the window unless it is repeated, which makes it a multi-sine with worse crest factor.

The lines are the requested log-spaced frequencies rounded to whole multiples of the base frequency ``f0`` (which
gives the period); points that round to the same line are one line.  ``f0`` divides ``from_hz`` and is as fine as the
log spacing asks at the low end, but never finer than ``1 / MAX_PERIOD_S`` (the periods must fit the recordings).
A line's amplitude grows as ``f^tilt``: a plant's response falls as 1/f (speed) and 1/f² (the recorded position), so
its measurement gives the high lines more (tilt 1); a closed loop's is flat up to its bandwidth (tilt ½).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from servostudio.errors import InvalidInput

#: the longest period: several periods must fit the recorder's memory at the control period's resolution
MAX_PERIOD_S = 0.4
#: the highest line a sample period allows: well below Nyquist, so a held sample still carries it
NYQUIST_SHARE = 0.45
#: rounds of peak clipping, and the share of the peak each clips to
CLIP_ROUNDS = 30
CLIP_SHARE = 0.85


class BadExcitation(InvalidInput):
    """An excitation that cannot be made (frequencies out of order or beyond the sample rate, too few points)."""


@dataclass(frozen=True)
class Multisine:
    """One period of the excitation: ``values`` (peak 1) at every sample, the excited harmonics of ``1 / period``."""

    harmonics: tuple[int, ...]
    samples: int
    sample_s: float
    values: tuple[float, ...]

    @property
    def period_s(self) -> float:
        return self.samples * self.sample_s

    @property
    def base_hz(self) -> float:
        return 1.0 / self.period_s

    @property
    def frequencies_hz(self) -> list[float]:
        return [harmonic * self.base_hz for harmonic in self.harmonics]

    def value(self, k: int) -> float:
        """The value of sample ``k`` of the endless periodic signal."""
        return self.values[k % self.samples]


def design(
    from_hz: float, to_hz: float, points: int, sample_s: float, tilt: float = 0.0, pattern: int = 1
) -> Multisine:
    """The multi-sine over ``from_hz`` … ``to_hz`` with up to ``points`` log-spaced lines, sampled every
    ``sample_s`` (the SYNC period), line amplitudes ∝ f^tilt.

    ``pattern``: the samples of a period are a multiple of it, and no two lines h, g (harmonic numbers) have
    h + g or |h − g| equal to ``samples / pattern`` — so whatever repeats every ``pattern`` samples (the 1-ms
    current monitor against a 0.75-ms SYNC: every 4) mixes each line only onto bins that carry none."""
    _check(from_hz, to_hz, points, sample_s)
    base = _base_frequency(from_hz, to_hz, points)
    samples = max(pattern, pattern * round(1.0 / (base * sample_s * pattern)))
    mirror = samples // pattern if pattern > 1 else None
    harmonics = _harmonics(from_hz, to_hz, points, 1.0 / (samples * sample_s), mirror)
    amplitudes = [(harmonic / harmonics[-1]) ** tilt for harmonic in harmonics]
    return Multisine(harmonics, samples, sample_s, tuple(_signal(harmonics, amplitudes, samples)))


def crest_factor(signal: Multisine) -> float:
    """Peak over RMS (1.41 for one sine)."""
    rms = math.sqrt(sum(value * value for value in signal.values) / signal.samples)
    return max(abs(value) for value in signal.values) / rms


def _check(from_hz: float, to_hz: float, points: int, sample_s: float) -> None:
    if not (0 < from_hz < to_hz) or not all(map(math.isfinite, (from_hz, to_hz))):
        raise BadExcitation(f"frequencies {from_hz:g} … {to_hz:g} Hz: give 0 < from < to")
    if not 2 <= points <= 400:
        raise BadExcitation(f"{points} points: give 2 … 400")
    highest = NYQUIST_SHARE / sample_s
    if to_hz > highest:
        raise BadExcitation(
            f"{to_hz:g} Hz is beyond what a sample every {sample_s * 1e3:g} ms carries ({highest:g} Hz)"
        )
    if from_hz < 1.0 / MAX_PERIOD_S:
        raise BadExcitation(
            f"{from_hz:g} Hz: the lowest frequency is {1.0 / MAX_PERIOD_S:g} Hz (a period of at most "
            f"{MAX_PERIOD_S:g} s must fit the recordings several times)"
        )


def _base_frequency(from_hz: float, to_hz: float, points: int) -> float:
    """``from_hz / m``: fine enough for the log spacing at the low end, not finer than the longest period allows."""
    ratio = (to_hz / from_hz) ** (1.0 / (points - 1))
    wanted = math.ceil(1.0 / (ratio - 1.0))
    allowed = max(1, math.floor(from_hz * MAX_PERIOD_S))
    return from_hz / min(wanted, allowed)


def _harmonics(from_hz: float, to_hz: float, points: int, base: float, mirror: int | None) -> tuple[int, ...]:
    """The log-spaced lines as harmonics of ``base``, low to high; a line that would pair with one chosen already
    across ``mirror`` (sum or difference equal to it) moves to the nearest free harmonic."""
    chosen: list[int] = []
    for n in range(points):
        wanted = max(1, round(from_hz * (to_hz / from_hz) ** (n / (points - 1)) / base))
        harmonic = _free(wanted, chosen, mirror)
        if harmonic is not None and harmonic not in chosen:
            chosen.append(harmonic)
    return tuple(sorted(chosen))


def _free(wanted: int, chosen: list[int], mirror: int | None) -> int | None:
    if mirror is None:
        return wanted
    for step in range(8):
        for harmonic in (wanted + step, wanted - step):
            clash = any(harmonic + other == mirror or abs(harmonic - other) == mirror for other in chosen)
            if harmonic >= 1 and harmonic != mirror and not clash:
                return harmonic
    return None


def _signal(harmonics: tuple[int, ...], amplitudes: list[float], samples: int) -> list[float]:
    """The lines with Schroeder's phases, then clipped rounds that lower the crest factor; scaled to peak 1."""
    count = len(harmonics)
    tables = _Tables(samples)
    phases = [-math.pi * k * (k - 1) / count for k in range(1, count + 1)]
    best = tables.synthesise(harmonics, amplitudes, phases)
    for _ in range(CLIP_ROUNDS):
        peak = max(abs(value) for value in best)
        limit = CLIP_SHARE * peak
        clipped = [min(max(value, -limit), limit) for value in best]
        candidate = tables.synthesise(harmonics, amplitudes, [tables.phase(clipped, h) for h in harmonics])
        if max(abs(value) for value in candidate) < peak:
            best = candidate
    peak = max(abs(value) for value in best)
    return [value / peak for value in best]


class _Tables:
    """cos and sin of 2π·i/samples, so a line costs a lookup per sample (h·i mod samples), no trigonometry."""

    def __init__(self, samples: int) -> None:
        self.samples = samples
        self.cos = [math.cos(2.0 * math.pi * i / samples) for i in range(samples)]
        self.sin = [math.sin(2.0 * math.pi * i / samples) for i in range(samples)]

    def synthesise(self, harmonics: tuple[int, ...], amplitudes: list[float], phases: list[float]) -> list[float]:
        """Σ a·cos(2π·h·i/samples + φ) = Σ a·(cos φ·cos − sin φ·sin)."""
        n, cos, sin = self.samples, self.cos, self.sin
        values = [0.0] * n
        for harmonic, amplitude, phase in zip(harmonics, amplitudes, phases, strict=True):
            c, s = amplitude * math.cos(phase), amplitude * math.sin(phase)
            for i in range(n):
                index = harmonic * i % n
                values[i] += c * cos[index] - s * sin[index]
        return values

    def phase(self, values: list[float], harmonic: int) -> float:
        """The phase of one line of ``values``: the angle of Σ v·e^{−j2π·h·i/samples}."""
        n = self.samples
        real = sum(value * self.cos[harmonic * i % n] for i, value in enumerate(values))
        imaginary = -sum(value * self.sin[harmonic * i % n] for i, value in enumerate(values))
        return math.atan2(imaginary, real)
