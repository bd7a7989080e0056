"""Offline parameter editing and compare on the XtrapulsPac dictionary."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from servostudio.od import Access, DataType, SaveType, Variable
from servostudio.services.projects import Axis, FileFormatError, ParameterRefused, ProjectService
from servostudio.services.projects.parameter_values import (
    BadValue,
    from_file_value,
    normalize,
    parse_text,
    to_file_value,
)


@pytest.fixture
def axis(sim_project: ProjectService) -> ProjectService:
    sim_project.store.add_axis("p", Axis("X", "xtrapulspac", 4, "sim"))
    return sim_project


def _files(service: ProjectService) -> dict[str, bytes]:
    directory = service.store.root / "p" / "X"
    return {path.name: path.read_bytes() for path in sorted(directory.iterdir())}


def test_values_go_to_the_file_their_save_type_names(axis: ProjectService):
    change = axis.parameters.set("p", "X", {"0x6060": "Sequence", "0x1006": 20000, "0x2004": "Lift axis"})
    assert [(row.variable.index, row.value, row.file) for row in change.rows] == [
        (0x6060, -3, "DRIVEPAR.TXT"),
        (0x1006, 20000, "USER_PAR.TXT"),
        (0x2004, "Lift axis", "DRIVEPAR.TXT"),
    ]
    files = _files(axis)
    assert files["DRIVEPAR.TXT"] == b"0x2004,0=Lift axis\n0x6060,0=-3\n"
    assert files["USER_PAR.TXT"] == b"0x1006,0=20000\n"


def test_rows_show_value_default_and_difference(axis: ProjectService):
    axis.parameters.set("p", "X", {"0x3051": 5, "0x3050,1": 0})
    row, _ = axis.parameters.get("p", "X", "0x3051")
    assert (row.value, row.default, row.differs_from_default, row.file) == (5, 0, True, "DRIVEPAR.TXT")
    same, _ = axis.parameters.get("p", "X", "0x3050,1")
    assert (same.value, same.default, same.differs_from_default, same.file) == (0, 0, False, "DRIVEPAR.TXT")
    untouched, _ = axis.parameters.get("p", "X", "0x1006")
    assert (untouched.value, untouched.file) == (10000, None)


def test_node_id_defaults_are_resolved_for_the_axis(axis: ProjectService):
    row, _ = axis.parameters.get("p", "X", "0x1014")
    assert row.default == 0x80 + 4


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"0x6410,14": 25}, r"0x6410,14 .*25 is outside 1\.\.24"),
        ({"0x6041": 0}, r"0x6041,0 .* is read-only \(ro\)"),
        ({"0x6040": 6}, r"0x6040,0 .* not saved in a drive file .* only be written to a live drive"),
        ({"0x7777": 1}, r"no object named '0x7777'"),
        ({"0x6060": "fast"}, r"'fast' is not a decimal or 0x hex integer or one of: Profile position"),
        ({"0x6060": 1.5}, r"INTEGER8 needs an integer"),
        ({"0x3051": 1, "0x6060": 200}, r"0x6060,0 .*200 is outside -128\.\.127"),
        ({"0x2004": "1st axis"}, r"DRIVEPAR.TXT: text value of 0x2004,0 starts like a number"),
    ],
)
def test_refused_writes_explain_and_write_nothing(axis: ProjectService, changes, message):
    axis.parameters.set("p", "X", {"0x3051": 7})
    before = _files(axis)
    revision = axis.store.open("p").revision
    with pytest.raises(ParameterRefused, match=message):
        axis.parameters.set("p", "X", changes)
    assert _files(axis) == before
    assert axis.store.open("p").revision == revision


def test_reset_returns_to_the_default(axis: ProjectService):
    axis.parameters.set("p", "X", {"0x3051": 5})
    change = axis.parameters.unset("p", "X", ["0x3051"])
    assert (change.rows[0].value, change.rows[0].file) == (0, None)
    assert _files(axis)["DRIVEPAR.TXT"] == b""


def test_a_value_moves_to_the_file_its_save_type_names(axis: ProjectService):
    directory = axis.store.root / "p" / "X"
    (directory / "USER_PAR.TXT").write_text("0x3051,0=9\n")
    row, _ = axis.parameters.get("p", "X", "0x3051")
    assert (row.value, row.file) == (9, "USER_PAR.TXT")
    axis.parameters.set("p", "X", {"0x3051": 2})
    assert _files(axis)["USER_PAR.TXT"] == b""
    assert _files(axis)["DRIVEPAR.TXT"] == b"0x3051,0=2\n"


def test_entries_unknown_to_the_dictionary_are_kept(axis: ProjectService):
    directory = axis.store.root / "p" / "X"
    (directory / "DRIVEPAR.TXT").write_text("; from a newer firmware\n0x5FFE,1=7\n")
    axis.parameters.set("p", "X", {"0x3051": 2})
    assert _files(axis)["DRIVEPAR.TXT"] == b"0x3051,0=2\n0x5FFE,1=7\n"


def test_broken_axis_file_names_file_and_line(axis: ProjectService):
    path = axis.store.root / "p" / "X" / "DRIVEPAR.TXT"
    path.write_text("0x3051,0=1\n0x2004,0=12\n")
    with pytest.raises(FileFormatError) as caught:
        axis.parameters.get("p", "X", "0x3051")
    assert (caught.value.file, caught.value.line) == ("p/X/DRIVEPAR.TXT", 2)  # its place in the project
    assert str(path.parent) not in str(caught.value) and str(caught.value).startswith("p/X/DRIVEPAR.TXT:2: ")
    assert "expected text" in caught.value.reason


def test_compare_lists_exactly_the_changed_objects(axis: ProjectService):
    axis.parameters.set("p", "X", {"0x3051": 5, "0x3050,2": 0x60FD0003, "0x1006": 20000, "0x3050,3": 0})
    rows, _ = axis.parameters.compare("p", "X", only_differences=True)
    assert {(row.variable.index, row.variable.subindex): row.values for row in rows} == {
        (0x1006, 0): {"project": 20000, "default": 10000},
        (0x3050, 2): {"project": 0x60FD0003, "default": 0},
        (0x3051, 0): {"project": 5, "default": 0},
    }
    io_group = axis.library.load("xtrapulspac")[0x3050, 2].group
    assert io_group != axis.library.load("xtrapulspac")[0x1006, 0].group
    digital, _ = axis.parameters.compare("p", "X", group=io_group.upper(), only_differences=True)
    assert [(row.variable.index, row.variable.subindex) for row in digital] == [(0x3050, 2), (0x3051, 0)]
    everything, _ = axis.parameters.compare("p", "X")
    assert len(everything) == sum(
        1 for v in axis.library.load("xtrapulspac").variables() if v.save_type is not SaveType.NONE
    )


def test_compare_takes_a_drive_column(axis: ProjectService):
    class Drive:
        def read(self, index: int, sub: int):
            return 1 if (index, sub) == (0x3051, 0) else axis.library.load("xtrapulspac")[index, sub].default_for(4)

    axis.parameters.set("p", "X", {"0x3051": 1, "0x3055": 2})
    rows, _ = axis.parameters.compare("p", "X", only_differences=True, drive=Drive())
    # against a drive only drive != project counts: 0x3051 matches the project although both differ from default
    assert [(row.variable.index, row.values) for row in rows] == [
        (0x3055, {"drive": 0, "project": 2, "default": 0}),
    ]
    all_rows, _ = axis.parameters.compare("p", "X", drive=Drive())
    same = next(row for row in all_rows if row.variable.key == (0x3051, 0))
    assert (same.values, same.differs) == ({"drive": 1, "project": 1, "default": 0}, False)


def _real(data_type: DataType) -> Variable:
    return Variable(0x2100, 0, "Gain", data_type, Access.RW, save_type=SaveType.DRIVEPAR)


@settings(deadline=None)  # no per-example time limit: the machine is shared
@given(st.floats(allow_nan=False, allow_infinity=False, width=32))
def test_real32_values_survive_the_object_file(value):
    variable = _real(DataType.REAL32)
    stored = to_file_value(variable, value)
    assert isinstance(stored, int) and 0 <= stored < 2**32
    assert from_file_value(variable, stored) == normalize(variable, value)


@settings(deadline=None)  # no per-example time limit: the machine is shared
@given(st.floats(allow_nan=False, allow_infinity=False))
def test_real64_values_survive_the_object_file(value):
    variable = _real(DataType.REAL64)
    assert from_file_value(variable, to_file_value(variable, value)) == value


@settings(deadline=None)  # no per-example time limit: the machine is shared
@given(st.text())
def test_user_text_parses_or_is_refused_with_the_object_name(text):
    variable = Variable(
        0x6060, 0, "Modes of operation", DataType.INTEGER8, Access.RW, enum={1: "Profile position", -3: "Sequence"}
    )
    try:
        value = parse_text(variable, text)
    except BadValue as error:
        assert "0x6060,0" in str(error)
    else:
        assert isinstance(value, int)


def test_float_text_is_parsed_for_real_objects():
    assert math.isclose(parse_text(_real(DataType.REAL32), "1.25"), 1.25)
    with pytest.raises(BadValue, match="not a number"):
        parse_text(_real(DataType.REAL32), "one")


def test_parameter_list_filters(axis: ProjectService):
    axis.parameters.set("p", "X", {"0x3051": 5})
    rows, _ = axis.parameters.rows("p", "X", only_set=True)
    assert [row.variable.key for row in rows] == [(0x3051, 0)]
    motor, _ = axis.parameters.rows("p", "X", group="Motor")
    assert motor and all(row.variable.group == "Motor" for row in motor)
    saved, _ = axis.parameters.rows("p", "X")
    every, _ = axis.parameters.rows("p", "X", include_unsaved=True)
    assert len(every) == len(axis.library.load("xtrapulspac")) > len(saved)
