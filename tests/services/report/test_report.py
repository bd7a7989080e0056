"""The commissioning report from a project's files alone: a simulated drive commissioned through the procedure
service (current loop, auto-phasing, auto-tuning with its verification step), its results saved in the project as
the service saves them, a capture saved by the scope's store, a frequency response by its store; then the report is
generated with no drive and checked for what it must hold."""

from __future__ import annotations

import hashlib
import json
import math
import shutil
from dataclasses import replace
from html.parser import HTMLParser
from pathlib import Path

import pytest
from tests.services.procedures.conftest import open_bench
from tests.services.procedures.test_procedures_plants import commission

from servostudio.od import builtin_library
from servostudio.services.audit import Actor, AuditLog, acting_as
from servostudio.services.frequency import store as frequency_store
from servostudio.services.procedures.recording import record
from servostudio.services.procedures.store import ResultStore
from servostudio.services.projects import ProjectService
from servostudio.services.report import report_html
from servostudio.services.scope import CaptureDefinition, CaptureStore
from servostudio.services.scope.service import identity_of

DEMO = Path(__file__).parents[3] / "projects" / "demo"
HOSTILE = '<script>alert("x")</script><img src=x onerror=alert(1)>'


class Page(HTMLParser):
    """What the tests look for in the document: script tags and their sources, element ids, text."""

    def __init__(self, html: str) -> None:
        super().__init__()
        self.scripts: list[dict[str, str | None]] = []
        self.ids: set[str] = set()
        self.text: list[str] = []
        self.feed(html)
        self.close()

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        if tag == "script":
            self.scripts.append(dict(attrs))
        self.ids.update(value for key, value in attrs if key == "id" and value)

    def handle_data(self, data: str) -> None:
        self.text.append(data)


def plotted(html: str, div_id: str) -> list[dict]:
    """The traces plotly draws in ``div_id``, read back from the page's own script."""
    start = html.index(f'Plotly.newPlot(                        "{div_id}",')
    data = html.index("[", start)
    return json.JSONDecoder().raw_decode(html, data)[0]


@pytest.fixture(scope="module")
def commissioned(tmp_path_factory):
    """The project after a commissioning of seed 101's hidden plant, with every record saved under axis X."""
    root = tmp_path_factory.mktemp("store")
    shutil.copytree(DEMO, root / "demo")
    audit = AuditLog(root / "audit.jsonl")
    projects = ProjectService(root, builtin_library(), audit=audit)
    bench = open_bench("1", seed=101, speed=5.0)
    try:
        plant, current, phasing, tuning = commission(bench, 75)
        drive = bench.machine()
        capture = record(drive, CaptureDefinition(channels=("velocity_actual",), period_us=500.0, samples=50),
                         lambda event: None)  # fmt: skip
        capture = replace(capture, drive=identity_of(bench.connection, drive))
    finally:
        bench.manager.close_all()
    results = ResultStore(projects.store)
    with acting_as(Actor("alice", "expert")):
        for name, result in (("current_loop", current), ("auto_phasing", phasing), ("auto_tuning", tuning)):
            results.save("demo", "X", name, result)
        CaptureStore(projects.store).save("demo", "X", capture, "identity")
        frequency_store.save(projects.store, "demo", "X", bode_of(plant), "plant sweep")
        projects.parameters.set("demo", "X", {"0x6410,11": 250})
        projects.store.edit_axis("demo", "Y", description=HOSTILE)
    return projects, audit, plant, tuning, phasing, capture


def bode_of(plant) -> dict:
    """A plant frequency response in the contract's shape (docs/frequency-response.md), of the true plant."""
    points = []
    for number in range(20):
        frequency = 5.0 * 1.2**number
        response = 1 / complex(plant.viscous_friction, 2 * math.pi * frequency * plant.total_inertia)
        points.append(
            {
                "freq_hz": frequency,
                "magnitude_db": 20 * math.log10(abs(response)),
                "phase_deg": math.degrees(math.atan2(response.imag, response.real)),
                "coherence": 0.99,
            }
        )
    return {
        "kind": "frequency_response",
        "loop": "plant",
        "node": 1,
        "device": "xtrapulspac",
        "axis": "X",
        "time": "2026-12-02T05:01:02Z",
        "user": "bob",
        "excitation": {"type": "multisine", "from_hz": 5},
        "points": points,
        "markers": {"bandwidth_hz": None, "resonance_hz": 180.0},
        "plant_fit": {"inertia_kgm2": 1.234e-4, "viscous_friction_nms_per_rad": 5.6e-5},
        "aborted": None,
    }


def test_the_report_holds_the_commissioning_of_the_axis(commissioned):
    projects, audit, _, tuning, phasing, capture = commissioned
    html = report_html(projects, "demo", audit=audit)
    page = Page(html)
    text = " ".join(page.text)
    assert f"{tuning['identified']['inertia_kgm2']:.6g}" in text  # the identified inertia, as the drive found it
    assert f"{tuning['identified']['viscous_friction_nms_per_rad']:.6g}" in text
    assert f"{1.234e-4:.6g}" in text  # the Bode plant fit beside it
    assert "pole_pairs" in text and str(phasing["pole_pairs"]) in text
    assert "kp_speed" in text and "Auto-tuning (drive)" in text and "bandwidth" in text
    assert "0x6410,11" in text and "Torque constant" in text  # the differing parameter
    drivepar = projects.store.project_directory("demo") / "X" / "DRIVEPAR.TXT"
    assert hashlib.sha256(drivepar.read_bytes()).hexdigest() in text
    assert "alice" in text and "bob" in text  # who: the audit log and the result's own user
    assert capture.drive.vendor_id is not None and f"0x{capture.drive.vendor_id:08X}" in text  # from the capture
    assert "saved capture 'identity'" in text


def test_the_plots_carry_the_saved_recordings(commissioned):
    projects, _, _, tuning, _, _ = commissioned
    html = report_html(projects, "demo", "X")
    step = tuning["verification"]["speed_step"]["capture"]
    traces = plotted(html, "axis-1-steps-0-speed_step")
    assert traces[0]["x"] == step["time_s"] and traces[1]["y"] == step["response"]
    bode = plotted(html, "axis-1-bode-plant")
    saved = frequency_store.load(projects.store.project_directory("demo"), "X", "plant sweep")
    assert bode[0]["y"] == pytest.approx([point["magnitude_db"] for point in saved["points"]])
    assert bode[1]["y"] == pytest.approx([point["phase_deg"] for point in saved["points"]])


def test_the_report_is_standalone_and_escapes_project_text(commissioned):
    projects, audit, *_ = commissioned
    html = report_html(projects, "demo", audit=audit)
    page = Page(html)
    assert all(script.get("src") is None for script in page.scripts)  # plotly.js inline, nothing loaded
    assert "Plotly.newPlot" in html and "plotly.js v" in html
    assert HOSTILE not in html and "&lt;script&gt;alert(&quot;x&quot;)&lt;/script&gt;" in html
    assert {"project", "axis-1", "axis-2", "axis-3", "axis-1-bode", "axis-2-phasing"} <= page.ids
    assert "@media print" in html and "break-before: page" in html


def test_sections_without_data_say_so(commissioned):
    projects, *_ = commissioned
    html = report_html(projects, "demo", "Z")
    text = " ".join(Page(html).text)
    assert "Axis X" not in text and "Axis Z" in text
    assert "Not phased from the tool yet" in text and "Not tuned from the tool yet" in text
    assert "No frequency response (Bode) saved" in text and "No step response saved" in text
    assert "Firmware and serial number not recorded" in text and "No audit log at hand" in text
