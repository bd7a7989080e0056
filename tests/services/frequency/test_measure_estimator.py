"""The excitation, the estimator and the markers on signals whose answer is known exactly (no drive): a multi-sine
that repeats, a discrete double integrator, analytic closed loops and a two-mass plant."""

from __future__ import annotations

import cmath
import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from servostudio.services.frequency import estimate, excitation, markers
from servostudio.services.frequency.excitation import BadExcitation

TWO_PI = 2.0 * math.pi


def test_the_multisine_has_distinct_lines_a_low_crest_factor_and_repeats():
    signal = excitation.design(5.0, 400.0, 60, 750e-6)
    assert signal.frequencies_hz[0] == pytest.approx(5.0, rel=0.01)
    assert signal.frequencies_hz[-1] == pytest.approx(400.0, rel=0.01)
    assert len(set(signal.harmonics)) == len(signal.harmonics) > 40
    assert max(abs(value) for value in signal.values) == pytest.approx(1.0)
    assert excitation.crest_factor(signal) < 3.0  # equal phases: √(2N) ≈ 9.6
    assert signal.value(3) == signal.value(3 + signal.samples)
    lines = estimate.block_lines(list(signal.values), range(1, signal.harmonics[-1] + 2), signal.samples)[0]
    excited = {harmonic - 1 for harmonic in signal.harmonics}
    assert all(abs(line) < 1e-9 for n, line in enumerate(lines) if n not in excited)  # no other line: no leakage


@pytest.mark.parametrize(("low", "high", "points"), [(0, 400, 60), (5, 2, 60), (5, 400, 1), (1, 400, 60), (5, 900, 60)])
def test_impossible_excitations_are_refused(low, high, points):
    with pytest.raises(BadExcitation):
        excitation.design(low, high, points, 750e-6)


def double_integrator(signal: excitation.Multisine, inertia: float, periods: int) -> tuple[list[float], list[float]]:
    """Torque → position of J·ω' = T, integrated as the simulator does (the period's torque, semi-implicit)."""
    dt, speed, angle = signal.sample_s, 0.0, 3.0
    positions, torques = [], []
    for k in range(signal.samples * (periods + 1)):
        torque = 0.2 * signal.value(k)
        speed += dt * torque / inertia
        angle += dt * (speed + 10.0)  # a base speed of 10 rad/s on top
        if k >= signal.samples:
            positions.append(angle)
            torques.append(torque)
    return positions, torques


def test_the_estimator_recovers_a_known_plant_from_positions_and_torques():
    signal = excitation.design(5.0, 300.0, 30, 1e-3)
    inertia = 4e-4
    positions, torques = double_integrator(signal, inertia, 3)
    frequencies = signal.frequencies_hz
    speed = estimate.speed_lines(estimate.position_lines(positions, signal.harmonics, signal.samples), frequencies)
    points = estimate.h1(estimate.block_lines(torques, signal.harmonics, signal.samples), speed, frequencies)
    for point in points:
        omega = TWO_PI * point.freq_hz
        x = omega * signal.sample_s / 2
        exact = cmath.exp(1j * omega * signal.sample_s) * (x / math.sin(x)) ** 2 / (1j * omega * inertia)
        assert point.value == pytest.approx(exact, rel=1e-6)
        assert point.coherence == pytest.approx(1.0)
    fit = estimate.rigid_fit(
        [
            estimate.Point(p.freq_hz, p.value / cmath.exp(1j * TWO_PI * p.freq_hz * 1e-3), 1.0)
            for p in points
            if p.freq_hz < 50
        ]
    )
    assert fit is not None and fit["inertia_kgm2"] == pytest.approx(inertia, rel=0.02)


@settings(max_examples=20, deadline=None)
@given(st.integers(0, 3), st.integers(0, 7))
def test_a_held_signal_is_taken_where_it_changes(phase, start):
    """A signal the drive updates every 4 records, recorded every record: its lines equal the lines of the
    instants it was taken at, whatever the recording's start."""
    block, hold, harmonic = 64, 4, 3
    values = [math.cos(TWO_PI * harmonic * i / block) for i in range(block * 2 + start + 8)]
    held = [values[i - (i - phase) % hold] for i in range(len(values))]
    taken = held[start : start + 2 * block]
    lines = estimate.held_lines(taken, [harmonic], block, hold)
    assert abs(lines[0][0]) == pytest.approx(block / 2, rel=1e-6)
    assert estimate.update_phase(taken, hold) == (phase - start) % hold


def points_of(freq: list[float], values: list[complex]) -> list[dict[str, float]]:
    return estimate.as_points([estimate.Point(f, v, 1.0) for f, v in zip(freq, values, strict=True)])


def log_grid(low: float, high: float, count: int) -> list[float]:
    return [low * (high / low) ** (n / (count - 1)) for n in range(count)]


def test_bandwidth_and_margins_of_an_analytic_loop():
    """L = ωc²(1 + s/z)/s² · e^{−sτ}: closed loop T = L/(1 + L); its markers against a dense direct evaluation."""
    wc, z, tau = TWO_PI * 60.0, TWO_PI * 15.0, 4e-4
    freq = log_grid(2.0, 1000.0, 400)

    def loop(f: float) -> complex:
        s = 1j * TWO_PI * f
        return wc**2 * (1 + s / z) / s**2 * cmath.exp(-s * tau)

    found = markers.markers_of("closed", points_of(freq, [loop(f) / (1 + loop(f)) for f in freq]))
    dense = log_grid(2.0, 1000.0, 20000)
    bandwidth = next(f for f in dense if abs(loop(f) / (1 + loop(f))) < 0.5**0.5)
    crossover = next(f for f in dense if abs(loop(f)) < 1.0)
    margin = 180.0 + math.degrees(cmath.phase(loop(crossover)))
    assert found["bandwidth_hz"] == pytest.approx(bandwidth, rel=0.01)
    assert found["phase_margin_deg"] == pytest.approx(margin, abs=1.0)
    assert found["resonance_hz"] is None


def test_resonance_and_antiresonance_of_a_two_mass_plant():
    jm, jl, k = 2e-4, 6e-4, 150.0
    freq = log_grid(5.0, 400.0, 200)

    def plant(f: float) -> complex:
        s = 1j * TWO_PI * f
        return (jl * s**2 + k) / (s * (jm * jl * s**2 + (jm + jl) * k))

    found = markers.markers_of("plant", points_of(freq, [plant(f) for f in freq]))
    assert found["resonance_hz"] == pytest.approx(math.sqrt(k * (jm + jl) / (jm * jl)) / TWO_PI, rel=0.02)
    assert found["antiresonance_hz"] == pytest.approx(math.sqrt(k / jl) / TWO_PI, rel=0.02)
    assert found["bandwidth_hz"] is None and found["phase_margin_deg"] is None
