"""``servostudio report PROJECT [AXIS] --out FILE.html``, offline from the project directory and through a running
server: a project commissioned on the simulator (seed 101's hidden plant, results saved as the services save them),
the report written as a real file, parsed, and checked for the saved records and the plots; the file is replaced
atomically and a refusal leaves the previous one whole."""

from __future__ import annotations

import pytest
from tests.support.commands import run_json
from tests.support.live_server import LiveServer
from tests.support.report_project import PLANT_FIT, Page, commissioned, plotted

from servostudio.services.audit import AuditLog


@pytest.fixture(scope="module")
def store(tmp_path_factory):
    """The project store with the commissioned demo project, and the data directory whose audit log saw it."""
    root = tmp_path_factory.mktemp("cli-report")
    (root / "projects").mkdir()
    (root / "data").mkdir()
    return root, commissioned(root / "projects", AuditLog(root / "data" / "audit.jsonl"))


@pytest.fixture(scope="module")
def server(store):
    """A real server on the same project store (a bus with no drives: the report needs none)."""
    root, _ = store
    live = LiveServer(root / "projects", ["--bus", "virtual:cli-report"], data_dir=None)
    try:
        live.wait_ready()
        yield live
    finally:
        live.stop()


@pytest.fixture(autouse=True)
def no_data_dir(monkeypatch, tmp_path):
    """Nor may the developer's data directory (users, tokens) reach the report commands."""
    monkeypatch.setenv("SERVOSTUDIO_DATA_DIR", str(tmp_path / "no-data"))


def test_the_project_report_is_written_offline_from_the_project_directory(store, tmp_path, capsys):
    root, record = store
    out = tmp_path / "demo.html"
    code, summary, _ = run_json(capsys, "report", "demo", "--out", str(out), "--projects", str(root / "projects"),
                           "--data-dir", str(root / "data"))  # fmt: skip
    assert code == 0 and summary["out"] == str(out) and summary["bytes"] == out.stat().st_size
    html = out.read_text(encoding="utf-8")
    page = Page(html)
    assert {"axis-1", "axis-2", "axis-3", "axis-1-bode"} <= page.ids
    assert all(script.get("src") is None for script in page.scripts)  # plotly.js inline: opens offline
    text = " ".join(page.text)
    assert f"{record.tuning['identified']['inertia_kgm2']:.6g}" in text and f"{PLANT_FIT['inertia_kgm2']:.6g}" in text
    assert "alice" in text  # who changed the project, from the data directory's audit log
    step = record.tuning["verification"]["speed_step"]["capture"]
    assert plotted(html, "axis-1-steps-0-speed_step")[0]["x"] == step["time_s"]


def test_an_axis_report_replaces_the_file_and_a_refusal_leaves_it_whole(store, tmp_path, capsys):
    root, _ = store
    out = tmp_path / "x.html"
    out.write_text("old")
    projects = ("--projects", str(root / "projects"))
    code, summary, _ = run_json(capsys, "report", "demo", "X", "--out", str(out), *projects)
    assert code == 0 and summary["axis"] == "X"
    text = " ".join(Page(out.read_text(encoding="utf-8")).text)
    assert "Axis X" in text and "Axis Y" not in text
    assert "No audit log at hand" in text  # no data directory with an audit log here
    before = out.read_bytes()
    code, _, error = run_json(capsys, "report", "demo", "Q", "--out", str(out), *projects)
    assert code == 4 and "no axis 'Q'" in error
    assert out.read_bytes() == before and sorted(path.name for path in tmp_path.glob("*.html*")) == ["x.html"]
    code, _, error = run_json(capsys, "report", "demo", "--out", str(tmp_path / "absent" / "r.html"), *projects)
    assert code == 3 and "does not exist" in error


def test_through_the_server_the_report_is_the_servers(store, server, tmp_path, capsys):
    _, record = store
    out = tmp_path / "served.html"
    code, summary, _ = run_json(capsys, "report", "demo", "X", "--out", str(out), "--server", server.url)
    assert code == 0 and summary["from"] == f"server {server.url}"
    html = out.read_text(encoding="utf-8")
    assert "Axis X" in " ".join(Page(html).text)
    step = record.tuning["verification"]["speed_step"]["capture"]
    assert plotted(html, "axis-1-steps-0-speed_step")[1]["y"] == step["response"]
    code, _, error = run_json(capsys, "report", "demo", "Q", "--out", str(out), "--server", server.url)
    assert code == 4 and "no axis 'Q'" in error


def test_an_unreachable_server_writes_nothing(tmp_path, capsys):
    out = tmp_path / "none.html"
    code, _, error = run_json(capsys, "report", "demo", "--out", str(out), "--server", "http://127.0.0.1:9")
    assert code == 5 and "cannot be reached" in error and not out.exists()
