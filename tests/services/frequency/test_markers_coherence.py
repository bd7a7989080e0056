"""The markers weigh coherence (docs/frequency-response.md §6), judged on synthetic responses whose true markers are
known: the cases in ``markers_cases.json`` are shared with the frontend's markers (frontend/src/__tests__/
markers_cases.test.ts), which must find the same values; hypothesis shows incoherent points never change a marker.

``python -m tests.services.frequency.test_markers_coherence`` writes the cases again (the truth from the models,
``found`` from the backend's markers).
"""

from __future__ import annotations

import cmath
import json
import math
import random
from collections.abc import Callable
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from servostudio.services.frequency import estimate, markers

CASES = Path(__file__).with_name("markers_cases.json")
TWO_PI = 2.0 * math.pi
KEYS = ("bandwidth_hz", "gain_margin_db", "phase_margin_deg", "resonance_hz", "antiresonance_hz")


def log_grid(low: float, high: float, count: int) -> list[float]:
    return [low * (high / low) ** (n / (count - 1)) for n in range(count)]


def points_of(freq: list[float], values: list[complex], coherence: list[float]) -> list[dict[str, float]]:
    points = [estimate.Point(f, v, c) for f, v, c in zip(freq, values, coherence, strict=True)]
    return estimate.as_points(points)


def noisy(freq: list[float], response: Callable[[float], complex], noise: dict[int, tuple[float, float]]) -> list:
    """The response with the points ``noise`` names (index → (gain in dB, coherence)) made incoherent noise; the
    others coherent (γ² 0.999)."""
    values = [response(f) * 10 ** (noise.get(n, (0.0, 0.0))[0] / 20.0) for n, f in enumerate(freq)]
    return points_of(freq, values, [noise.get(n, (0.0, 0.999))[1] for n in range(len(freq))])


def rigid(f: float) -> complex:
    return 1.0 / (3e-4 * 1j * TWO_PI * f + 2e-3)


JM, JL, K = 2e-4, 4e-4, 2e-4 * 4e-4 / 6e-4 * (TWO_PI * 140.0) ** 2


def two_mass(f: float) -> complex:
    s = 1j * TWO_PI * f
    damping = 0.05 * 2 * math.sqrt(K * JM * JL / (JM + JL))
    load = JL * s**2 + damping * s + K
    return load / (s * (JM * load + JL * (damping * s + K)))


WC, ZERO, TAU = TWO_PI * 60.0, TWO_PI * 15.0, 4e-4


def loop(f: float) -> complex:
    s = 1j * TWO_PI * f
    return WC**2 * (1 + s / ZERO) / s**2 * cmath.exp(-s * TAU)


def closed(f: float) -> complex:
    return loop(f) / (1 + loop(f))


def loop_truth() -> dict[str, float]:
    """The analytic loop's markers from a dense direct evaluation."""
    dense = log_grid(2.0, 2000.0, 40000)
    bandwidth = next(f for f in dense if abs(closed(f)) < 0.5**0.5)
    crossover = next(f for f in dense if abs(loop(f)) < 1.0)
    phase_crossover = next(f for f in dense if math.degrees(cmath.phase(loop(f))) > 0 and f > crossover)
    return {
        "bandwidth_hz": bandwidth,
        "phase_margin_deg": 180.0 + math.degrees(cmath.phase(loop(crossover))),
        "gain_margin_db": -20.0 * math.log10(abs(loop(phase_crossover))),
    }


def build() -> list[dict]:
    """The cases: name, loop (plant, closed, or open: margins of L itself), points, truth with its tolerance."""
    plant_grid, loop_grid = log_grid(5.0, 400.0, 46), log_grid(2.0, 1000.0, 120)
    top = {n: (gain, 0.6 + 0.05 * k) for k, (n, gain) in enumerate(((40, 5.0), (42, 7.0), (43, -6.0), (45, 4.0)))}
    anti, resonance = math.sqrt(K / JL) / TWO_PI, math.sqrt(K * (JM + JL) / (JM * JL)) / TWO_PI
    spike = {plant_grid.index(min(plant_grid, key=lambda f: abs(f - 250.0))): (12.0, 0.5)}
    # dips the noise of a loaded host digs among the top points (γ² between the dip and the marker thresholds)
    top_dips = {40: (-5.0, 0.86), 43: (-7.0, 0.9)}
    truth = loop_truth()
    near_bandwidth = min(range(len(loop_grid)), key=lambda n: abs(loop_grid[n] - 0.6 * truth["bandwidth_hz"]))
    near_crossover = {near_bandwidth: (-12.0, 0.3), near_bandwidth + 1: (8.0, 0.8)}
    incoherent = {n: (0.0, 0.5) for n in range(len(loop_grid))}
    cases = [
        ("rigid plant, incoherent noise at the top", "plant", noisy(plant_grid, rigid, top), {}),
        ("two-mass plant, coherent resonance, an incoherent spike", "plant", noisy(plant_grid, two_mass, spike),
         {"resonance_hz": resonance, "antiresonance_hz": anti}),
        ("rigid plant, dips of γ² 0.86-0.9 at the top", "plant", noisy(plant_grid, rigid, top_dips), {}),
        ("two-mass plant, a deeper dip of γ² 0.86-0.9 above the resonance", "plant",
         noisy(plant_grid, two_mass, top_dips), {"resonance_hz": resonance, "antiresonance_hz": anti}),
        ("two-mass plant, every point incoherent", "plant",
         noisy(plant_grid, two_mass, {n: (0.0, 0.7) for n in range(46)}), {}),
        ("closed loop, incoherent points before the bandwidth", "closed", noisy(loop_grid, closed, near_crossover),
         truth),
        ("closed loop, every point incoherent", "closed", noisy(loop_grid, closed, incoherent), {}),
        ("open loop, incoherent points near the crossover", "open", noisy(loop_grid, loop, near_crossover),
         {key: truth[key] for key in ("gain_margin_db", "phase_margin_deg")}),
    ]  # fmt: skip
    tolerance = {"bandwidth_hz": 0.02, "resonance_hz": 0.03, "antiresonance_hz": 0.05}
    return [
        {"name": name, "loop": kind, "points": points, "found": found(kind, points),
         "truth": {key: None if key not in true else {"value": true[key], "rel": tolerance.get(key), "abs": 1.5}
                   for key in KEYS if key in marked(kind)}}
        for name, kind, points, true in cases
    ]  # fmt: skip


def marked(kind: str) -> tuple[str, ...]:
    return {"plant": KEYS[3:], "closed": KEYS[:3], "open": KEYS[1:3]}[kind]


def found(kind: str, points: list[dict[str, float]]) -> dict[str, float | None]:
    """What the backend marks on a case (an open loop: the margins of its coherent points)."""
    if kind != "open":
        return {key: value for key, value in markers.markers_of(kind, points).items() if key in marked(kind)}
    usable = markers.coherent(points)
    freq = [point["freq_hz"] for point in usable]
    return markers.margins(freq, [p["magnitude_db"] for p in usable], [p["phase_deg"] for p in usable])


def near(value: float | None, truth: dict | None) -> bool:
    if truth is None or value is None:
        return truth is None and value is None
    if truth["rel"] is not None:
        return value == pytest.approx(truth["value"], rel=truth["rel"])
    return value == pytest.approx(truth["value"], abs=truth["abs"])


def same(value: float | None, expected: float | None) -> bool:
    return value == expected if value is None or expected is None else value == pytest.approx(expected, rel=1e-9)


SHARED = json.loads(CASES.read_text())


@pytest.mark.parametrize("case", SHARED, ids=[case["name"] for case in SHARED])
def test_the_markers_are_the_true_ones_and_the_shared_table_s(case):
    got = found(case["loop"], case["points"])
    assert got.keys() == case["found"].keys()
    assert all(same(got[key], value) for key, value in case["found"].items()), (got, case["found"])
    assert all(near(got[key], truth) for key, truth in case["truth"].items()), (got, case["truth"])


def test_the_shared_table_is_what_the_cases_build():
    assert json.loads(json.dumps(build())) == SHARED


def with_incoherent(points: list[dict[str, float]], seed: int, count: int) -> list[dict[str, float]]:
    """``count`` points of random magnitude, phase and sub-threshold coherence inserted at random frequencies."""
    rng = random.Random(seed)
    extra = [
        {"freq_hz": rng.uniform(2.0, 1000.0), "magnitude_db": rng.uniform(-60.0, 80.0),
         "phase_deg": rng.uniform(-400.0, 100.0), "coherence": rng.uniform(0.0, markers.MIN_DIP_COHERENCE * 0.999)}
        for _ in range(count)
    ]  # fmt: skip
    return sorted([*points, *extra], key=lambda point: point["freq_hz"])


@settings(max_examples=60, deadline=None)
@given(case=st.sampled_from(SHARED), seed=st.integers(0, 2**32), count=st.integers(1, 20))
def test_incoherent_points_never_change_a_marker(case, seed, count):
    kind = "closed" if case["loop"] == "open" else case["loop"]
    points = case["points"]
    assert markers.markers_of(kind, with_incoherent(points, seed, count)) == markers.markers_of(kind, points)


@settings(max_examples=40, deadline=None)
@given(coherence=st.lists(st.floats(0.0, markers.MIN_COHERENCE * 0.999), min_size=46, max_size=46))
def test_a_response_with_no_coherent_point_is_marked_with_nothing(coherence):
    freq = log_grid(5.0, 400.0, 46)
    for kind, response in (("plant", two_mass), ("closed", closed)):
        points = points_of(freq, [response(f) for f in freq], coherence)
        assert all(value is None for value in markers.markers_of(kind, points).values())


if __name__ == "__main__":
    CASES.write_text(json.dumps(build(), indent=1) + "\n")
