"""Procedure results kept in the project: under their axis, newest first, and never a change of the project's
settings (a saved result must not turn another client's next parameter write into a revision conflict)."""

from __future__ import annotations

import shutil
from datetime import UTC, datetime
from pathlib import Path

from servostudio.od import builtin_library
from servostudio.services.audit import Actor, acting_as
from servostudio.services.procedures.store import ResultStore
from servostudio.services.projects import ProjectService

DEMO = Path(__file__).parents[3] / "projects" / "demo"


def test_results_are_listed_newest_first_and_leave_the_revision_alone(tmp_path):
    shutil.copytree(DEMO, tmp_path / "demo")
    projects = ProjectService(tmp_path, builtin_library())
    store = ResultStore(projects.store)
    before = projects.store.open("demo").revision
    first = store.save("demo", "X", "auto_tuning", {"status": "done", "n": 1}, datetime(2026, 1, 1, tzinfo=UTC))
    second = store.save("demo", "X", "auto_phasing", {"status": "done", "n": 2}, datetime(2026, 1, 2, tzinfo=UTC))
    assert first.startswith("X/procedures/auto_tuning-") and second.startswith("X/procedures/auto_phasing-")
    assert [result["n"] for result in store.list("demo", "X")] == [2, 1]
    assert projects.store.open("demo").revision == before


def test_a_result_records_who_ran_it(tmp_path):
    """The commissioning report's "who": the user the procedure ran for, or the one a result already names."""
    shutil.copytree(DEMO, tmp_path / "demo")
    store = ResultStore(ProjectService(tmp_path, builtin_library()).store)
    with acting_as(Actor("alice", "expert")):
        store.save("demo", "X", "auto_tuning", {"status": "done"}, datetime(2026, 1, 1, tzinfo=UTC))
        store.save("demo", "X", "auto_phasing", {"status": "done", "user": "bob"}, datetime(2026, 1, 2, tzinfo=UTC))
    assert [result["user"] for result in store.list("demo", "X")] == ["bob", "alice"]
