"""Step metrics on responses whose truth is known analytically: a first-order loop of 80 Hz seen through a 200 Hz
measurement filter, and a second-order loop with a known overshoot."""

from __future__ import annotations

import math

import pytest

from servostudio.services.procedures.stepmetrics import step_metrics

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
