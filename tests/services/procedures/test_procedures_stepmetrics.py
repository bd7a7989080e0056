"""Step metrics on responses whose truth is known analytically: a first-order loop of 80 Hz seen through a 200 Hz
measurement filter, and a second-order loop with a known overshoot."""

from __future__ import annotations

import math

import pytest

from servostudio.services.procedures.stepmetrics import mean_bandwidth, step_metrics, window

DT = 250e-6


def _simulate(steps: int, derivative) -> tuple[list[float], list[float], list[float]]:
    times = [(n - 80) * DT for n in range(steps)]
    reference = [0.0 if t < 0 else 100.0 for t in times]
    state = [0.0, 0.0, 0.0]
    response = []
    for r in reference:
        for _ in range(10):  # sub-steps for accuracy
            state = [x + DT / 10 * dx for x, dx in zip(state, derivative(state, r), strict=True)]
        response.append(state[-1])
    return times, reference, response


def test_a_first_order_loop_behind_a_measurement_filter():
    loop, sensor = 2 * math.pi * 80, 2 * math.pi * 200
    times, reference, response = _simulate(1200, lambda s, r: [loop * (r - s[0]), 0.0, sensor * (s[0] - s[2])])
    metrics = step_metrics(times, reference, response, filters_hz=(200.0,))
    assert metrics.bandwidth_hz == pytest.approx(80.0, rel=0.05)
    assert metrics.overshoot_pct == pytest.approx(0.0, abs=0.1)
    assert metrics.settling_time_s is not None and metrics.rise_time_s is not None


def test_a_second_order_loop_overshoots_as_its_damping_says():
    wn, zeta = 2 * math.pi * 60, 0.5
    # position, speed, and the position again as the measured output (no filter)
    times, reference, response = _simulate(1600, lambda s, r: [s[1], wn * wn * (r - s[0]) - 2 * zeta * wn * s[1], s[1]])
    expected = 100 * math.exp(-zeta * math.pi / math.sqrt(1 - zeta * zeta))
    assert step_metrics(times, reference, response).overshoot_pct == pytest.approx(expected, abs=1.0)


def test_the_mean_response_of_a_rising_and_a_falling_step_of_one_loop():
    """Two steps of an 80 Hz loop, one up and one down, each with its own quantisation of the measured output (as
    the drive's speed is quantised): the bandwidth of their mean response is the loop's."""
    loop = 2 * math.pi * 80

    def recorded(height: float, offset: float):
        times, reference, response = _simulate(1200, lambda s, r: [loop * (r - s[0]), 0.0, loop * 10 * (s[0] - s[2])])
        quantised = [round((value * height / 100 + offset) / 0.7) * 0.7 for value in response]
        return window(times, [value * height / 100 + offset for value in reference], quantised)

    up, down = recorded(100.0, 0.0), recorded(-100.0, 20.0)
    assert up is not None and down is not None
    assert mean_bandwidth([up, down]) == pytest.approx(80.0, rel=0.05)
    assert mean_bandwidth([]) is None
