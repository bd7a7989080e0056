"""Cancelling project commissioning mid-way (the job's Cancellation, set from the progress of the first file)."""

from __future__ import annotations

import pytest

from servostudio.services.cancel import Cancellation
from servostudio.services.projects import Axis, Bus


@pytest.fixture(scope="module")
def project(service):
    """Project 'pc': axis Z on node 3 of the embedded simulated bus."""
    service.store.create("pc", "cancel test", (Bus("sim", "sim"),))
    service.store.add_axis("pc", Axis("Z", "xtrapulspac", 3, "sim"))
    service.parameters.set("pc", "Z", {"0x6081": 4096})
    return "pc"


def _cancel_at_first_step(operation: str):
    cancel = Cancellation()

    def progress(event):
        if event.get("operation") == operation and event.get("done", 0) > 0:
            cancel.cancel()

    return cancel, progress


def test_cancelled_download_reports_what_was_written_and_stores_nothing(project, live):
    cancel, progress = _cancel_at_first_step("restore")
    report = live.commission(project, "download", progress=progress, cancel=cancel)
    (axis,) = report.axes
    assert not axis.ok
    (first,) = axis.files  # the files after the cancelled one were not started
    assert first["file"] == "DRIVEPAR.TXT" and first["cancelled"] is True and first["stored"] == ""
    assert first["counts"].get("not written", 0) > 0
    assert (
        f"{first['counts'].get('written', 0)} of {sum(first['counts'].values())} objects were written" in first["error"]
    )


def test_cancelled_upload_leaves_the_project_unchanged(project, live, service):
    before = service.store.open(project).revision
    files = {path.name: path.read_bytes() for path in (service.store.root / project / "Z").iterdir()}
    cancel, progress = _cancel_at_first_step("backup")
    report = live.commission(project, "upload", progress=progress, cancel=cancel)
    (axis,) = report.axes
    assert axis.error == "upload cancelled; the project was not changed" and not axis.ok
    assert report.revision == before == service.store.open(project).revision
    assert {path.name: path.read_bytes() for path in (service.store.root / project / "Z").iterdir()} == files
