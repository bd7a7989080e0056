"""Saved frequency responses over REST: a plant response of a true rigid plant saved by the store, listed, read back
with its points and the markers its points have (not the ones it was saved with), downloaded as the pinned CSV and
as a standalone HTML file holding the traces, plotly.js inline and a true two-mass plant's resonance, overlaid with
another, deleted by an Expert only; unknown names and damaged files refused with their reason. No drive is needed:
saved results are project records."""

from __future__ import annotations

import json
import math
import re
import shutil
from pathlib import Path

import pytest
from tests.support.access import admin_app, api_client

from servostudio.api.app import Settings
from servostudio.services.frequency import store
from servostudio.services.users import Level

DEMO = Path(__file__).parents[2] / "projects" / "demo"
BASE = "/api/projects/demo/axes/X/frequency"
INERTIA, FRICTION = 3.6e-4, 2.0e-4


def true_plant(name_hz: float = 5.0, points: int = 30) -> dict:
    """The result dict of a plant measurement of 1/(J·s + B), exactly, with NaN coherence on the last point."""
    rows = []
    for number in range(points):
        frequency = name_hz * 1.15**number
        value = 1 / complex(FRICTION, 2 * math.pi * frequency * INERTIA)
        rows.append({"freq_hz": frequency, "magnitude_db": 20 * math.log10(abs(value)),
                     "phase_deg": math.degrees(math.atan2(value.imag, value.real)), "coherence": 0.98})  # fmt: skip
    rows[-1]["coherence"] = math.nan
    return {
        "kind": "frequency_response", "loop": "plant", "node": 1, "device": "xtrapulspac", "axis": "X",
        "time": "2026-12-02T08:00:00Z", "user": "alice",
        "excitation": {"type": "multisine", "from_hz": 5, "to_hz": 400, "points": points, "amplitude_pct": 10},
        "points": rows,
        "markers": {"bandwidth_hz": None, "gain_margin_db": None, "phase_margin_deg": None,
                    "resonance_hz": 123.0, "antiresonance_hz": None},  # stale: a rigid plant has none
        "plant_fit": {"inertia_kgm2": INERTIA, "viscous_friction_nms_per_rad": FRICTION},
        "gains": {"kp_a_per_rad_s": 0.2}, "aborted": None,
    }  # fmt: skip


JM, JL, RESONANCE_HZ = 2e-4, 4e-4, 140.0


def two_mass_plant() -> dict:
    """A plant measurement of a motor J_M coupled to a load J_L, resonating at 140 Hz (lightly damped)."""
    stiffness = JM * JL / (JM + JL) * (2 * math.pi * RESONANCE_HZ) ** 2
    damping = 0.05 * 2 * math.sqrt(stiffness * JM * JL / (JM + JL))
    rows = []
    for number in range(40):
        frequency = 5.0 * 1.1**number
        s = complex(0, 2 * math.pi * frequency)
        load = JL * s**2 + damping * s + stiffness
        value = load / (s * (JM * load + JL * (damping * s + stiffness)))
        rows.append({"freq_hz": frequency, "magnitude_db": 20 * math.log10(abs(value)),
                     "phase_deg": math.degrees(math.atan2(value.imag, value.real)), "coherence": 0.99})  # fmt: skip
    return {**true_plant(), "time": "2026-12-01T08:00:00Z", "points": rows, "markers": None}


@pytest.fixture(scope="module")
def app(tmp_path_factory):
    root = tmp_path_factory.mktemp("frequency-saved")
    shutil.copytree(DEMO, root / "projects" / "demo")
    settings = Settings(projects_dir=root / "projects", static_dir=root / "no-ui", buses=())
    app = admin_app(settings, root / "data")
    projects = app.state.server.projects.store
    store.save(projects, "demo", "X", true_plant(), "rigid")
    store.save(projects, "demo", "X", two_mass_plant(), "two-mass")
    store.save(projects, "demo", "X", {**true_plant(8.0, 12), "loop": "closed", "time": "2026-12-02T09:00:00Z"})
    return app


@pytest.fixture
def client(app):
    with api_client(app) as client:
        yield client


def test_listed_newest_first_and_read_back_with_its_points(client):
    listed = client.get(BASE).json()
    assert [item["loop"] for item in listed] == ["closed", "plant", "plant"]
    assert listed[1]["name"] == "rigid" and listed[1]["markers"]["resonance_hz"] is None  # not the 123 Hz saved
    full = client.get(f"{BASE}/rigid").json()
    written = true_plant()["points"]
    assert len(full["points"]) == len(written)
    for got, want in zip(full["points"][:-1], written, strict=False):
        assert got["magnitude_db"] == pytest.approx(want["magnitude_db"], rel=1e-5)
        assert got["phase_deg"] == pytest.approx(want["phase_deg"], rel=1e-5)
    assert full["points"][-1]["coherence"] is None  # NaN in the CSV, null in JSON
    assert full["plant_fit"] == {"inertia_kgm2": INERTIA, "viscous_friction_nms_per_rad": FRICTION}
    assert full["gains"] == {"kp_a_per_rad_s": 0.2}


def test_the_csv_has_the_pinned_columns(client):
    answer = client.get(f"{BASE}/rigid/csv")
    assert answer.status_code == 200 and answer.headers["content-type"].startswith("text/csv")
    assert 'filename="rigid.csv"' in answer.headers["content-disposition"]
    lines = [line for line in answer.text.splitlines() if not line.startswith("#")]
    assert lines[0] == "freq_hz,magnitude_db,phase_deg,coherence"
    assert store.parse_points(answer.text)[0]["freq_hz"] == pytest.approx(5.0)
    assert lines[-1].endswith(",nan")


def plotted(document: str) -> list[dict]:
    start = document.index('Plotly.newPlot(                        "bode",')
    return json.JSONDecoder().raw_decode(document, document.index("[", start))[0]


def test_the_html_is_standalone_with_the_traces_and_markers(client):
    other = client.get(BASE).json()[0]["name"]
    answer = client.get(f"{BASE}/rigid/html", params={"compare": [other, "two-mass"]})
    assert answer.status_code == 200 and answer.headers["content-type"].startswith("text/html")
    document = answer.text
    assert not re.search(r"<script[^>]+src=", document)  # plotly.js inline: opens offline
    traces = plotted(document)
    assert len(traces) == 9  # magnitude, phase, coherence of the three results
    assert traces[0]["y"][0] == pytest.approx(true_plant()["points"][0]["magnitude_db"], rel=1e-5)
    resonance = client.get(f"{BASE}/two-mass").json()["markers"]["resonance_hz"]
    assert resonance == pytest.approx(RESONANCE_HZ, rel=0.05)
    assert f"resonance {resonance:.4g} Hz" in document and "123 Hz" not in document


def test_unknown_names_and_damaged_files_are_refused(client, app):
    assert client.get(f"{BASE}/nothing").status_code == 404
    assert client.get("/api/projects/demo/axes/NOAXIS/frequency").status_code == 404
    assert client.get(f"{BASE}/rigid/html", params={"compare": ["nothing"]}).status_code == 404
    directory = app.state.server.projects.store.project_directory("demo") / "X" / "frequency"
    store.save(app.state.server.projects.store, "demo", "X", true_plant(), "broken")
    (directory / "broken.csv").write_text("freq_hz,magnitude_db,phase_deg,coherence\n1,2,x,4\n", encoding="utf-8")
    answer = client.get(f"{BASE}/broken")
    assert answer.status_code == 422 and "X/frequency/broken.csv:2" in answer.json()["detail"]
    assert client.delete(f"{BASE}/broken").status_code == 204  # a damaged result can still be removed
    assert not (directory / "broken.json").exists() and not (directory / "broken.csv").exists()


def test_reading_is_the_operators_and_deleting_the_experts(app):
    store.save(app.state.server.projects.store, "demo", "X", true_plant(), "doomed")
    with api_client(app, Level.OPERATOR) as operator:
        assert operator.get(f"{BASE}/doomed").status_code == 200
        assert operator.delete(f"{BASE}/doomed").status_code == 403
    with api_client(app, Level.MAINTENANCE) as maintenance:
        assert maintenance.delete(f"{BASE}/doomed").status_code == 403
    with api_client(app, Level.EXPERT) as expert:
        assert expert.delete(f"{BASE}/doomed").status_code == 204
        assert expert.get(f"{BASE}/doomed").status_code == 404
        assert expert.delete(f"{BASE}/doomed").status_code == 404
