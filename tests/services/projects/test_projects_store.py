"""Project store: create, open, list, rename, duplicate, delete; axes with their validation; stable files."""

from __future__ import annotations

import difflib
from pathlib import Path

import pytest

from servostudio.services.projects import (
    Axis,
    Bus,
    ConflictError,
    FileFormatError,
    InvalidName,
    ProjectExists,
    ProjectNotFound,
    ProjectService,
    ValidationError,
)
from servostudio.services.projects.model import from_text


def _tree(root: Path) -> dict[str, bytes]:
    return {path.relative_to(root).as_posix(): path.read_bytes() for path in sorted(root.rglob("*")) if path.is_file()}


def test_created_project_is_listed_and_reads_back(service: ProjectService):
    snapshot = service.store.create("Line 1", "packaging line", (Bus("can0", "socketcan:can0", 500_000),))
    assert service.store.names() == ["Line 1"]
    opened = service.store.open("Line 1")
    assert opened.project.description == "packaging line"
    assert opened.project.buses == (Bus("can0", "socketcan:can0", 500_000),)
    assert opened.revision == snapshot.revision
    assert (service.store.root / "Line 1" / "project.toml").is_file()


def test_axes_get_a_directory_with_the_drive_files(sim_project: ProjectService):
    store = sim_project.store
    store.add_axis("p", Axis("X", "xtrapulspac", 1, "sim"))
    store.add_axis("p", Axis("Y", "cd1k", 100, "sim"))
    project = store.open("p").project
    assert [(a.name, a.device, a.node_id) for a in project.axes] == [("X", "xtrapulspac", 1), ("Y", "cd1k", 100)]
    assert sorted(p.name for p in (store.root / "p" / "X").iterdir()) == [
        "DRIVEPAR.TXT",
        "SEQUENCE.TXT",
        "USER_PAR.TXT",
    ]
    assert sorted(p.name for p in (store.root / "p" / "Y").iterdir()) == ["DRIVEPAR.TXT"]


@pytest.mark.parametrize(
    ("axis", "message"),
    [
        (Axis("X", "xtrapulspac", 64, "sim"), "node ID 64 is out of range 1-63"),
        (Axis("X", "xtrapulspac", 0, "sim"), "out of range 1-63"),
        (Axis("X", "cd1k", 128, "sim"), "out of range 1-127"),
        (Axis("X", "xtrapulspac", 1, "nobus"), "unknown bus 'nobus'"),
        (Axis("X", "nodevice", 1, "sim"), "unknown device 'nodevice'"),
        (Axis("A", "xtrapulspac", 5, "sim"), "node ID 5 on bus 'sim' is already used by axis 'first'"),
        (Axis("FIRST", "cd1k", 6, "sim"), "used twice"),
        (Axis("B", "cd1k", 69, "sim"), "node ID 69 on bus 'sim' is reserved by axis 'first'"),
    ],
)
def test_axis_rules_refuse_and_write_nothing(sim_project: ProjectService, axis: Axis, message: str):
    store = sim_project.store
    store.add_axis("p", Axis("first", "xtrapulspac", 5, "sim"))
    before = _tree(store.root)
    with pytest.raises(ValidationError, match=message):
        store.add_axis("p", axis)
    assert _tree(store.root) == before


@pytest.mark.parametrize("name", ["../evil", "a/b", "", ".hidden", "CON", "x" * 65, "trailing.", "tab\tname"])
def test_unsafe_names_are_refused(sim_project: ProjectService, name: str):
    with pytest.raises(InvalidName):
        sim_project.store.add_axis("p", Axis(name, "xtrapulspac", 1, "sim"))
    with pytest.raises(InvalidName):
        sim_project.store.create(name)
    assert sim_project.store.names() == ["p"]


def test_same_node_on_two_buses_is_fine(service: ProjectService):
    service.store.create("p", buses=(Bus("a", "sim"), Bus("b", "socketcan:can1")))
    service.store.add_axis("p", Axis("X", "xtrapulspac", 1, "a"))
    service.store.add_axis("p", Axis("Y", "xtrapulspac", 1, "b"))
    assert len(service.store.open("p").project.axes) == 2


def test_edit_axis_renames_its_directory_and_keeps_files(sim_project: ProjectService):
    store = sim_project.store
    store.add_axis("p", Axis("X", "xtrapulspac", 1, "sim"))
    sim_project.parameters.set("p", "X", {"0x6060": 1})
    store.edit_axis("p", "X", name="Lift", node_id=7)
    axis = store.open("p").project.axis("Lift")
    assert axis is not None and axis.node_id == 7
    assert not (store.root / "p" / "X").exists()
    assert (store.root / "p" / "Lift" / "DRIVEPAR.TXT").read_text() == "0x6060,0=1\n"


def test_remove_axis_deletes_its_directory(sim_project: ProjectService):
    store = sim_project.store
    store.add_axis("p", Axis("X", "xtrapulspac", 1, "sim"))
    store.remove_axis("p", "X")
    assert store.open("p").project.axes == ()
    assert sorted(p.name for p in (store.root / "p").iterdir()) == ["project.toml"]
    with pytest.raises(ProjectNotFound, match="no axis 'X'"):
        store.remove_axis("p", "X")


def test_rename_duplicate_delete(sim_project: ProjectService):
    store = sim_project.store
    store.add_axis("p", Axis("X", "xtrapulspac", 1, "sim"))
    store.rename("p", "q")
    assert store.names() == ["q"]
    assert store.open("q").project.name == "q"
    copy = store.duplicate("q", "r")
    assert copy.project.axes == store.open("q").project.axes
    assert (store.root / "r" / "X" / "DRIVEPAR.TXT").is_file()
    with pytest.raises(ProjectExists):
        store.duplicate("q", "R")
    store.delete("q")
    assert store.names() == ["r"]
    assert sorted(p.name for p in store.root.iterdir()) == ["r"]
    with pytest.raises(ProjectNotFound):
        store.open("q")


def test_stale_revision_is_a_conflict_and_writes_nothing(sim_project: ProjectService):
    store = sim_project.store
    seen = store.open("p").revision
    store.add_axis("p", Axis("X", "xtrapulspac", 1, "sim"), expected_revision=seen)
    before = _tree(store.root)
    with pytest.raises(ConflictError, match="changed by someone else"):
        store.add_axis("p", Axis("Y", "xtrapulspac", 2, "sim"), expected_revision=seen)
    with pytest.raises(ConflictError):
        sim_project.parameters.set("p", "X", {"0x6060": 1}, expected_revision=seen)
    assert _tree(store.root) == before


def test_writing_the_same_project_twice_is_byte_identical(sim_project: ProjectService):
    store = sim_project.store
    store.add_axis("p", Axis("X", "xtrapulspac", 1, "sim"))
    first = _tree(store.root)
    store.update("p", description="test project")
    sim_project.parameters.set("p", "X", {"0x6060": 1})
    sim_project.parameters.set("p", "X", {"0x6060": 1})
    second = _tree(store.root)
    sim_project.parameters.set("p", "X", {"0x6060": 1})
    assert _tree(store.root) == second
    assert second["p/project.toml"] == first["p/project.toml"]


def test_one_change_is_a_one_line_diff(sim_project: ProjectService):
    store = sim_project.store
    for name, node in (("X", 1), ("Y", 2), ("Z", 3)):
        store.add_axis("p", Axis(name, "xtrapulspac", node, "sim"))
    sim_project.parameters.set("p", "Y", {"0x6060": 1, "0x3051": 3, "0x3050,1": 0x60FD0003})
    before = _tree(store.root)
    store.edit_axis("p", "Y", node_id=9)
    sim_project.parameters.set("p", "Y", {"0x3051": 4})
    after = _tree(store.root)
    changed = {path for path in after if after[path] != before[path]}
    assert changed == {"p/project.toml", "p/Y/DRIVEPAR.TXT"}
    for path in changed:
        diff = [
            line
            for line in difflib.unified_diff(
                before[path].decode().splitlines(), after[path].decode().splitlines(), lineterm="", n=0
            )
            if line[:1] in "+-" and not line.startswith(("+++", "---"))
        ]
        assert len(diff) == 2, diff


def test_hand_broken_project_file_names_file_and_line(sim_project: ProjectService):
    path = sim_project.store.root / "p" / "project.toml"
    path.write_text(path.read_text() + '\n[axis.X]\ndevice = "xtrapulspac"\nnode_id = "one"\nbus = "sim"\n')
    with pytest.raises(FileFormatError) as caught:
        sim_project.store.open("p")
    assert caught.value.file == "p/project.toml"  # its place in the project, not the server path
    assert str(sim_project.store.root) not in str(caught.value)
    assert caught.value.line == path.read_text().splitlines().index('node_id = "one"') + 1
    assert "'node_id' must be an integer" in caught.value.reason


def test_directory_name_wins_over_the_name_key(sim_project: ProjectService):
    root = sim_project.store.root
    (root / "p").rename(root / "copied")
    assert sim_project.store.open("copied").project.name == "copied"


def test_project_file_parser_rejects_unknown_keys():
    text = '[project]\nformat = 1\ncolour = "red"\n'
    with pytest.raises(FileFormatError, match="unknown key 'colour'"):
        from_text(text, "x.toml", "x")


def test_device_change_only_for_an_axis_without_values(sim_project: ProjectService):
    store = sim_project.store
    store.add_axis("p", Axis("X", "xtrapulspac", 1, "sim"))
    store.edit_axis("p", "X", device="cd1k")
    assert sorted(p.name for p in (store.root / "p" / "X").iterdir()) == ["DRIVEPAR.TXT"]
    sim_project.parameters.set("p", "X", {"0x3070": 1})
    before = _tree(store.root)
    with pytest.raises(ValidationError, match="holds values for device 'cd1k'"):
        store.edit_axis("p", "X", device="xtrapulspac")
    assert _tree(store.root) == before


def test_removing_a_bus_in_use_is_refused(sim_project: ProjectService):
    sim_project.store.add_axis("p", Axis("X", "xtrapulspac", 1, "sim"))
    with pytest.raises(ValidationError, match="unknown bus 'sim'"):
        sim_project.store.update("p", buses=(Bus("can0", "socketcan:can0"),))
    assert sim_project.store.open("p").project.buses == (Bus("sim", "sim", 1_000_000),)


def test_bus_interfaces_are_bus_specs(service: ProjectService):
    with pytest.raises(ValidationError, match=r"bus 'b': .*unknown interface 'fieldbus'"):
        service.store.create("p", buses=(Bus("b", "fieldbus:0"),))
    assert service.store.names() == []
