"""Saved frequency responses: the pinned CSV columns round-trip exactly (to the 6 significant digits written),
a damaged file is refused with its place in the project and the line, and names are never taken twice."""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from servostudio.od import builtin_library
from servostudio.services.frequency import store
from servostudio.services.projects import ProjectService

DEMO = Path(__file__).parents[3] / "projects" / "demo"

finite = st.floats(min_value=-1e9, max_value=1e9, allow_nan=False, allow_infinity=False)
point = st.fixed_dictionaries(
    {"freq_hz": st.floats(0.01, 1e5), "magnitude_db": finite, "phase_deg": st.floats(-720, 720),
     "coherence": st.one_of(st.floats(0, 1), st.just(math.nan))}
)  # fmt: skip


@given(st.lists(point, max_size=40))
def test_points_round_trip_through_the_pinned_csv(points):
    text = store.points_csv({"loop": "plant", "points": points})
    assert (
        next(line for line in text.splitlines() if not line.startswith("#"))
        == "freq_hz,magnitude_db,phase_deg,coherence"
    )
    for written, read in zip(points, store.parse_points(text), strict=True):
        for column in store.COLUMNS:
            if math.isnan(written[column]):
                assert math.isnan(read[column])
            else:
                assert read[column] == pytest.approx(written[column], rel=1e-5, abs=1e-300)


@given(st.text(max_size=200))
def test_any_text_is_either_points_or_a_file_error(text):
    try:
        points = store.parse_points(text, "X/frequency/a.csv")
    except store.FrequencyFileError as error:
        assert str(error).startswith("X/frequency/a.csv")
    else:
        assert all(set(item) == set(store.COLUMNS) for item in points)


def test_a_damaged_line_is_named():
    text = "freq_hz,magnitude_db,phase_deg,coherence\n1,2,3,0.9\n2,x,3,0.9\n"
    with pytest.raises(store.FrequencyFileError, match=r"a\.csv:3: not a number"):
        store.parse_points(text, "a.csv")
    with pytest.raises(store.FrequencyFileError, match=r"a\.csv:2: 4 values expected, 3 found"):
        store.parse_points("freq_hz,magnitude_db,phase_deg,coherence\n1,2,3\n", "a.csv")


@pytest.fixture
def projects(tmp_path):
    shutil.copytree(DEMO, tmp_path / "demo")
    return ProjectService(tmp_path, builtin_library())


def result(time: str) -> dict:
    points = [
        {"freq_hz": 10.0 * n, "magnitude_db": -3.0 * n, "phase_deg": -10.0 * n, "coherence": 0.98} for n in (1, 2)
    ]
    return {"kind": "frequency_response", "loop": "closed_loop", "node": 1, "time": time, "points": points}


def test_saved_results_list_newest_first_and_load_with_their_points(projects):
    first = store.save(projects.store, "demo", "X", result("2026-12-02T05:01:02Z"))
    second = store.save(projects.store, "demo", "X", result("2026-12-02T05:01:02Z"))
    named = store.save(projects.store, "demo", "X", result("2026-12-03T00:00:00Z"), "after filter")
    assert (first, second, named) == ("2026-12-02 05-01-02", "2026-12-02 05-01-02-2", "after filter")
    project_dir = projects.store.root / "demo"
    assert next(item["name"] for item in store.list_saved(project_dir, "X")) == "after filter"
    loaded = store.load(project_dir, "X", first)
    assert loaded["loop"] == "closed_loop" and loaded["points"][1]["magnitude_db"] == -6.0
    with pytest.raises(store.FrequencyResultExists):
        store.save(projects.store, "demo", "X", result("2026-12-04T00:00:00Z"), "AFTER FILTER")


def test_a_damaged_sidecar_lists_with_its_reason_and_a_missing_csv_is_refused(projects):
    name = store.save(projects.store, "demo", "X", result("2026-12-02T05:01:02Z"))
    directory = projects.store.root / "demo" / "X" / "frequency"
    (directory / "broken.json").write_text("{not json", encoding="utf-8")
    listed = {item["name"]: item for item in store.list_saved(directory.parents[1], "X")}
    assert "X/frequency/broken.json: cannot be read" in listed["broken"]["error"]
    (directory / f"{name}.csv").unlink()
    with pytest.raises(store.FrequencyFileError, match="the file is missing"):
        store.load(directory.parents[1], "X", name)
    with pytest.raises(store.FrequencyResultNotFound):
        store.load(directory.parents[1], "X", "nothing")


def test_a_saved_result_is_read_with_the_markers_its_points_have_today(projects):
    """Markers are derived data: a plant saved with an anti-resonance the old definition dug out of a rigid plant's
    noise reads without it; a two-mass plant's resonance is found from its points alone."""
    freq = [5.0 * 1.1**n for n in range(46)]
    rigid = [{"freq_hz": f, "magnitude_db": -20 * math.log10(2 * math.pi * f * 3e-4), "phase_deg": -90.0,
              "coherence": 0.99} for f in freq]  # fmt: skip
    stale = {"resonance_hz": None, "antiresonance_hz": 335.8, "bandwidth_hz": None}
    saved = {"kind": "frequency_response", "loop": "plant", "time": "2026-12-02T05:01:02Z", "markers": stale}
    name = store.save(projects.store, "demo", "X", {**saved, "points": rigid})
    project_dir = projects.store.root / "demo"
    assert store.load(project_dir, "X", name)["markers"]["antiresonance_hz"] is None
    assert store.list_saved(project_dir, "X")[0]["markers"]["antiresonance_hz"] is None
