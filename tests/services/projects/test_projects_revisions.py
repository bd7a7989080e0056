"""Kept revisions: a change that replaces many values keeps the project as it was, and restoring it brings back the
same files (and revision), itself undoable."""

from __future__ import annotations

import pytest

from servostudio.services.projects import Axis, ParameterRefused, ProjectNotFound, ProjectService
from servostudio.services.projects.revisions import KEEP


@pytest.fixture
def axis_project(sim_project: ProjectService) -> ProjectService:
    sim_project.store.add_axis("p", Axis("X", "xtrapulspac", 1, "sim"))
    return sim_project


def _files(service: ProjectService) -> dict[str, bytes]:
    root = service.store.root / "p"
    return {p.relative_to(root).as_posix(): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()}


def test_a_kept_change_can_be_restored_to_the_same_files_and_revision(axis_project: ProjectService):
    service = axis_project
    first = service.parameters.set("p", "X", {"0x60F9,2": 1200})
    before = {k: v for k, v in _files(service).items() if not k.startswith(".revisions/")}
    replaced = service.parameters.set("p", "X", {"0x60F9,2": 900, "0x6075": 2500}, keep="backup of node 1")
    assert replaced.revision != first.revision
    kept = service.revisions("p")
    assert [(item.revision, item.reason) for item in kept] == [(first.revision, "backup of node 1")]

    restored = service.restore_revision("p", first.revision, replaced.revision)
    assert restored.revision == first.revision
    assert service.parameters.get("p", "X", "0x60F9,2")[0].value == 1200
    assert service.parameters.get("p", "X", "0x6075")[0].file is None
    assert {k: v for k, v in _files(service).items() if not k.startswith(".revisions/")} == before
    # the restore kept what it replaced: undo the undo
    assert service.revisions("p")[0].revision == replaced.revision
    assert service.restore_revision("p", replaced.revision).revision == replaced.revision


def test_an_unkept_or_refused_change_keeps_nothing(axis_project: ProjectService):
    service = axis_project
    service.parameters.set("p", "X", {"0x60F9,2": 1200})
    with pytest.raises(ParameterRefused, match="outside"):
        service.parameters.set("p", "X", {"0x60F9,2": 10**9}, keep="refused")
    service.parameters.set("p", "X", {"0x60F9,2": 1200}, keep="unchanged")  # same value: the revision stays
    assert service.revisions("p") == []
    with pytest.raises(ProjectNotFound, match="keeps no revision 'abc'"):
        service.restore_revision("p", "abc")


def test_restoring_removes_an_axis_added_since_and_only_the_newest_are_kept(axis_project: ProjectService):
    service = axis_project
    original = service.store.open("p").revision
    service.parameters.set("p", "X", {"0x60F9,2": 1100}, keep="first")
    service.store.add_axis("p", Axis("Y", "xtrapulspac", 2, "sim"))
    service.restore_revision("p", original)
    assert [axis.name for axis in service.store.open("p").project.axes] == ["X"]
    assert not (service.store.root / "p" / "Y").exists()
    service.store.add_axis("p", Axis("Y", "xtrapulspac", 2, "sim"))  # the name is free again
    for value in range(KEEP + 2):
        service.parameters.set("p", "X", {"0x60F9,2": 1000 + value}, keep=f"change {value}")
    reasons = [item.reason for item in service.revisions("p")]
    assert len(reasons) == KEEP and reasons[0] == f"change {KEEP + 1}"
