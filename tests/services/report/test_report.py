"""The commissioning report from a project's files alone: a simulated drive commissioned through the procedure
service (current loop, auto-phasing, auto-tuning with its verification step), its results saved in the project as
the service saves them, a capture saved by the scope's store, a frequency response by its store; then the report is
generated with no drive and checked for what it must hold."""

from __future__ import annotations

import hashlib

import pytest
from tests.support.report_project import Page, plotted
from tests.support.report_project import commissioned as commission_project

from servostudio.services.audit import Actor, AuditLog, acting_as
from servostudio.services.frequency import store as frequency_store
from servostudio.services.report import report_html

HOSTILE = '<script>alert("x")</script><img src=x onerror=alert(1)>'


@pytest.fixture(scope="module")
def commissioned(tmp_path_factory):
    """The project after a commissioning of seed 101's hidden plant, with every record saved under axis X."""
    root = tmp_path_factory.mktemp("store")
    audit = AuditLog(root / "audit.jsonl")
    made = commission_project(root, audit)
    with acting_as(Actor("alice", "expert")):
        made.projects.store.edit_axis("demo", "Y", description=HOSTILE)
    return made.projects, audit, made.plant, made.tuning, made.phasing, made.capture


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
