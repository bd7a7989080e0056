"""The commissioning report over REST: a project commissioned on the simulator (seed 101's hidden plant, results
saved as the services save them), then downloaded whole and for one axis as standalone HTML, parsed, and checked
for the saved records and the plots; the audit history only for callers who may read the audit log; unknown
projects and axes refused. No drive is needed: the report is made from the project's files."""

from __future__ import annotations

import pytest
from tests.support.access import admin_app, api_client
from tests.support.report_project import BODE_NAME, PLANT_FIT, Page, commissioned, plotted

from servostudio.api.app import Settings
from servostudio.services.audit import AuditLog
from servostudio.services.frequency import store as frequency_store
from servostudio.services.users import Level


@pytest.fixture(scope="module")
def made(tmp_path_factory):
    root = tmp_path_factory.mktemp("report-api")
    (root / "projects").mkdir()
    settings = Settings(projects_dir=root / "projects", static_dir=root / "no-ui", buses=())
    app = admin_app(settings, root / "data")
    return app, commissioned(root / "projects", AuditLog(app.state.server.settings.audit_path))


def test_the_project_report_is_a_standalone_download_of_every_axis(made):
    app, record = made
    with api_client(app) as client:
        answer = client.get("/api/projects/demo/report")
    assert answer.status_code == 200 and answer.headers["content-type"].startswith("text/html")
    assert 'filename="demo-report.html"' in answer.headers["content-disposition"]
    page = Page(answer.text)
    assert {"project", "axis-1", "axis-2", "axis-3", "axis-1-bode"} <= page.ids
    assert all(script.get("src") is None for script in page.scripts)  # plotly.js inline: opens offline
    text = " ".join(page.text)
    assert f"{record.tuning['identified']['inertia_kgm2']:.6g}" in text
    assert f"{PLANT_FIT['inertia_kgm2']:.6g}" in text
    assert "alice" in text and "No audit log at hand" not in text  # the administrator sees who changed what


def test_one_axis_report_holds_that_axis_and_its_plots(made):
    app, record = made
    with api_client(app) as client:
        answer = client.get("/api/projects/demo/report", params={"axis": "X"})
    assert answer.status_code == 200
    assert 'filename="demo-X-report.html"' in answer.headers["content-disposition"]
    text = " ".join(Page(answer.text).text)
    assert "Axis X" in text and "Axis Y" not in text and "Axis Z" not in text
    step = record.tuning["verification"]["speed_step"]["capture"]
    assert plotted(answer.text, "axis-1-steps-0-speed_step")[1]["y"] == step["response"]
    saved = frequency_store.load(record.projects.store.project_directory("demo"), "X", BODE_NAME)
    bode = plotted(answer.text, "axis-1-bode-plant")
    assert bode[0]["y"] == pytest.approx([point["magnitude_db"] for point in saved["points"]])


def test_an_operator_gets_the_report_without_the_audit_history(made):
    app, record = made
    with api_client(app, Level.OPERATOR) as operator:
        answer = operator.get("/api/projects/demo/report", params={"axis": "X"})
    assert answer.status_code == 200
    text = " ".join(Page(answer.text).text)
    assert "No audit log at hand" in text and "needs the Expert level" in text
    assert f"{record.tuning['identified']['inertia_kgm2']:.6g}" in text  # everything else is there


@pytest.mark.parametrize(
    ("path", "params", "detail"),
    [("/api/projects/nowhere/report", {}, "nowhere"), ("/api/projects/demo/report", {"axis": "Q"}, "no axis 'Q'")],
)
def test_unknown_projects_and_axes_are_not_found(made, path, params, detail):
    app, _ = made
    with api_client(app) as client:
        answer = client.get(path, params=params)
    assert answer.status_code == 404 and answer.json()["kind"] == "not_found"
    assert detail in answer.json()["detail"]
