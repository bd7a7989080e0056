"""Scan into a project: the simulated bus's three XtrapulsPac drives become axes, checked by the store's rules."""

from __future__ import annotations

import pytest

from servostudio.services.projects import Axis, Bus, ValidationError


def test_scan_turns_every_identified_node_into_an_axis(live, service):
    service.store.create("s")
    report = live.scan("s", "sim")
    assert (report.bus, report.bus_added) == (Bus("sim", "sim"), True)
    assert [(node.identity.node, node.status, node.axis) for node in report.nodes] == [
        (1, "added", "Axis1"),
        (2, "added", "Axis2"),
        (3, "added", "Axis3"),
    ]
    project = service.store.open("s").project
    assert [(axis.name, axis.device, axis.node_id, axis.bus) for axis in project.axes] == [
        ("Axis1", "xtrapulspac", 1, "sim"),
        ("Axis2", "xtrapulspac", 2, "sim"),
        ("Axis3", "xtrapulspac", 3, "sim"),
    ]
    axis_dir = service.store.root / "s" / "Axis2"
    assert sorted(path.name for path in axis_dir.iterdir()) == ["DRIVEPAR.TXT", "SEQUENCE.TXT", "USER_PAR.TXT"]
    revision = report.snapshot.revision
    again = live.scan("s", "sim")
    assert [node.status for node in again.nodes] == ["present"] * 3 and not again.bus_added
    assert again.snapshot.revision == revision  # nothing new, nothing written


def test_scan_keeps_existing_axes_and_reports_conflicts(live, service):
    service.store.create("c", buses=(Bus("line", "sim"),))
    service.store.add_axis("c", Axis("Axis1", "cd1k", 2, "line"))
    report = live.scan("c", "sim")  # the same spec as bus 'line': that bus is used, none is added
    assert report.bus.name == "line" and not report.bus_added
    assert [(node.identity.node, node.status, node.axis) for node in report.nodes] == [
        (1, "added", "Axis1-line"),
        (2, "conflict", "Axis1"),
        (3, "added", "Axis3"),
    ]
    assert "expects device 'cd1k'" in report.nodes[1].reason
    assert [axis.name for axis in service.store.open("c").project.axes] == ["Axis1", "Axis1-line", "Axis3"]


def test_scan_refuses_what_is_neither_a_bus_nor_a_spec(live, service):
    service.store.create("n")
    with pytest.raises(ValidationError, match="neither a bus of project 'n'"):
        live.scan("n", "nonsense:0")
    assert service.store.open("n").project.buses == ()
