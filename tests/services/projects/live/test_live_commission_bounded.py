"""The wait for each axis of a commissioning is bounded (docs/reliability.md): an axis whose work never ends (a
stuck bus reader) is reported overdue, and the other axes and the job end, instead of an un-timed wait."""

from __future__ import annotations

import threading
import time

import pytest

from servostudio.services.projects import Axis, Bus
from servostudio.services.projects.live import commission as commissioning


@pytest.fixture(scope="module")
def project(service):
    """Project 'pb': axes A and B on nodes 1 and 2 of the embedded simulated bus."""
    service.store.create("pb", "bounded wait test", (Bus("sim", "sim"),))
    service.store.add_axis("pb", Axis("A", "xtrapulspac", 1, "sim"))
    service.store.add_axis("pb", Axis("B", "xtrapulspac", 2, "sim"))
    return "pb"


def test_an_axis_that_never_ends_is_reported_overdue_and_the_job_ends(project, live, monkeypatch) -> None:
    stuck = threading.Event()

    def download(report, *args, **kwargs) -> None:
        if report.link.axis.name == "A":
            stuck.wait(30)  # a bus reader that never delivers

    monkeypatch.setattr(commissioning, "_download", download)
    monkeypatch.setattr(commissioning, "AXIS_SAFETY_WAIT", 0.5)
    started = time.monotonic()
    try:
        report = live.commission(project, "download")
    finally:
        stuck.set()
    assert time.monotonic() - started < 5
    first, second = report.axes
    assert not first.ok and first.error.startswith("no outcome of axis A within")
    assert second.error == ""
