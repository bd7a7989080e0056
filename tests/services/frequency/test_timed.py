"""The time-based estimator of a free-running drive's response (services/frequency/timed.py) on signals whose answer
is known exactly: answers at jittered instants on a 250-µs control grid, as the free-running encoTRive gives them
(docs/frequency-response.md §8). The measurement itself is judged against hidden plants in test_measure_tpdo.py."""

from __future__ import annotations

import cmath
import itertools
import math
import random

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from servostudio.services.frequency import timed
from servostudio.services.frequency.excitation import design

TC = 250e-6
PERIOD = 0.4


def jittered(seed: int, seconds: float = 1.0) -> list[float]:
    """SYNC instants 0.75 ms apart with σ 0.3 ms (the Python producer on a loaded host), on the control grid."""
    rng, t, instants = random.Random(seed), 0.0, []
    while t < seconds:
        t += max(2e-4, rng.gauss(7.5e-4, 3e-4))
        instants.append(math.floor(t / TC) * TC)
    return instants


@settings(max_examples=20, deadline=None)
@given(st.integers(0, 10**6), st.integers(1, 80), st.floats(0.0, 2 * math.pi))
def test_the_speed_line_from_jittered_positions_is_exact_for_a_line(seed, harmonic, phase):
    """Position = base ramp + a line: the speed's line is jω·A whatever the instants (the ramp drops out)."""
    instants, omega, amplitude = jittered(seed), 2 * math.pi * harmonic / PERIOD, 0.3
    positions = [15.0 * t + amplitude * math.cos(omega * t + phase) for t in instants]
    line = timed.speed_line(instants, positions, omega, instants[3], 2 * PERIOD)
    want = 1j * omega * amplitude * cmath.exp(1j * phase)
    assert abs(line - want) < 0.01 * abs(want)


def test_the_staircase_line_is_the_integral_of_the_held_values():
    instants = jittered(7)
    held = [math.sin(40 * t) + 0.3 * math.cos(700 * t) for t in instants]
    start, length, omega = instants[10], 2 * PERIOD, 2 * math.pi * 25 / PERIOD
    fine = 64
    exact = timed.staircase_line(instants, held, omega, start, length)
    numeric = 0j
    for k in range(len(instants) - 1):
        width = (instants[k + 1] - instants[k]) / fine
        for r in range(fine):
            t = instants[k] + (r + 0.5) * width
            if start <= t < start + length:
                weight = 1 - math.cos(2 * math.pi * (t - start) / length)
                numeric += held[k] * weight * cmath.exp(-1j * omega * t) * width
    assert exact == pytest.approx(2 * numeric / length, abs=1e-3 * abs(exact))


@pytest.mark.parametrize("phase", [0, 1, 2, 3])
def test_the_monitor_s_grid_is_found_from_where_its_values_change(phase):
    """0x6078 refreshed every 4 control periods (at ``phase`` modulo 4) with the current of the period before:
    sampled at jittered SYNCs, each refresh lands on its own instant and a line of it comes out exact."""
    instants = jittered(3)
    periods = [round(t / TC) for t in instants]
    omega = 2 * math.pi * 30 / PERIOD

    def current(n: int) -> float:
        return math.cos(omega * n * TC) + 0.01 * n % 1

    held = [current(4 * ((n - phase) // 4) + phase - 1) for n in periods]
    times, values = timed.monitored(periods, held, 4, TC, TC)
    assert timed.refresh_phase(periods, held, 4) == phase
    seen = {4 * ((n - phase) // 4) + phase - 1 for n in periods}  # refreshes a SYNC saw (the rest interpolated)
    measured = [(round(t / TC), value) for t, value in zip(times, values, strict=True) if round(t / TC) in seen]
    assert len(measured) == len(seen) and all(value == pytest.approx(current(n)) for n, value in measured)
    assert all(b - a == pytest.approx(4 * TC) for a, b in itertools.pairwise(times))
    line = timed.grid_line(times, [math.cos(omega * t) for t in times], omega, times[5], 2 * PERIOD, 4 * TC)
    assert line == pytest.approx(1.0, abs=1e-9)


def test_the_excitation_in_time_is_the_designed_sequence_at_its_instants():
    signal = design(5.0, 200.0, 30, 750e-6, 0.0, 4)
    excitation = timed.Excitation(signal)
    for k in range(0, signal.samples, 37):
        assert excitation.at(k * signal.sample_s + 3 * signal.period_s) == pytest.approx(signal.value(k), abs=1e-9)


def test_the_drive_clock_follows_the_smallest_delay_of_the_answers():
    clock = timed.DriveClock()
    assert clock.now() is None
    for k, delay in enumerate([0.004, 0.002, 0.003]):
        clock.answered(10.0 + k, 1000.0 + k + delay)
    assert clock.lag == pytest.approx(990.002)


def test_a_window_with_a_stalled_sync_is_not_used():
    """A SYNC held back beyond MAX_GAP_S (a stalled host) leaves a step and its transient: the two windows that
    hold the gap are skipped and later ones taken."""
    instants = [k * 7.5e-4 for k in range(8000)]
    assert timed.clean_windows(instants, PERIOD, 4, False) == pytest.approx([0.0, PERIOD, 2 * PERIOD, 3 * PERIOD])
    stalled = [t + (0.02 if t > 1.0 else 0.0) for t in instants]  # 20 ms without a SYNC at 1 s
    assert timed.clean_windows(stalled, PERIOD, 4, False) == pytest.approx([0.0, 3 * PERIOD, 4 * PERIOD, 5 * PERIOD])
    assert timed.clean_windows(stalled, PERIOD, 13, False) is None  # not enough clean ones yet
    least_stalled = [k * PERIOD for k in range(14) if k != 2]  # time is up: the 12 clean ones and one stalled
    assert timed.clean_windows(stalled, PERIOD, 13, True) == pytest.approx(least_stalled)
