"""The demo project shipped in projects/demo matches the simulated drives: three XtrapulsPac, nodes 1-3, bus sim."""

from __future__ import annotations

from pathlib import Path

from servostudio.od import builtin_library
from servostudio.services.projects import ProjectService
from servostudio.services.projects.model import from_text, to_text
from servostudio.sim.network import parse_node_list
from servostudio.transport.spec import parse_bus_spec

PROJECTS = Path(__file__).resolve().parents[3] / "projects"


def test_demo_project_opens_and_is_valid():
    service = ProjectService(PROJECTS, builtin_library())
    project = service.store.open("demo").project
    assert [(bus.name, bus.interface) for bus in project.buses] == [("sim", "sim")]
    assert [(axis.name, axis.device, axis.node_id, axis.bus) for axis in project.axes] == [
        ("X", "xtrapulspac", 1, "sim"),
        ("Y", "xtrapulspac", 2, "sim"),
        ("Z", "xtrapulspac", 3, "sim"),
    ]
    simulated = parse_node_list(parse_bus_spec("sim").channel)
    assert [(node.node_id, node.device) for node in simulated] == [
        (1, "xtrapulspac"),
        (2, "xtrapulspac"),
        (3, "xtrapulspac"),
    ]
    for axis in project.axes:
        rows, _ = service.parameters.rows("demo", axis.name, only_set=True)
        assert rows == []


def test_demo_project_file_is_in_canonical_form():
    path = PROJECTS / "demo" / "project.toml"
    text = path.read_text(encoding="utf-8")
    assert to_text(from_text(text, path, "demo")) == text
