"""Motor catalog: text files, "Add new motor", selection for an axis with the drive's documented copy rules."""

from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from servostudio.services.projects import (
    Axis,
    FileFormatError,
    Motor,
    MotorCatalog,
    ParameterRefused,
    ProjectExists,
    ProjectService,
    ValidationError,
)
from servostudio.services.projects.motors import BUILTIN_MOTORS_DIR, motor_from_text, motor_to_text
from servostudio.services.projects.motorselect import current_limits

# Test data only: a made-up motor, not a real catalog entry.
TEST_MOTOR = Motor(
    reference="TEST-MOTOR-1",
    description="made-up motor for the tests",
    source="test data",
    motor_data={
        "manufacturer": "Test",
        "model": "T1",
        "motor_type": 0,
        "max_speed": 4500,
        "rated_speed": 3000,
        "stall_current": 2500,
        "peak_current": 7500,
        "torque_constant": 620,
        "inertia": 18,
        "inductance": 85,
        "pole_pairs": 4,
        "phase_order": 0x5555,
        "sensor_offset": 1200,
    },
    objects={(0x3324, 1): -1, (0x3324, 2): 2400},
)


@pytest.fixture
def catalog(service: ProjectService) -> MotorCatalog:
    service.motors.add(TEST_MOTOR)
    return service.motors


def test_added_motor_is_listed_and_stored_as_text(catalog: MotorCatalog):
    [motor] = catalog.motors()
    assert motor == TEST_MOTOR
    text = (catalog.user_dir / "TEST-MOTOR-1.toml").read_text()
    assert '[motor_data]\nmanufacturer = "Test"\nmodel = "T1"\nmotor_type = 0\nmax_speed = 4500\n' in text
    assert '"0x3324,1" = -1' in text
    assert motor_from_text(motor_to_text(motor), "x") == TEST_MOTOR


def test_a_reference_is_added_only_once(catalog: MotorCatalog):
    with pytest.raises(ProjectExists):
        catalog.add(TEST_MOTOR)


def test_builtin_motors_cannot_be_shadowed(tmp_path: Path):
    builtin = tmp_path / "builtin"
    builtin.mkdir()
    (builtin / "TEST-MOTOR-1.toml").write_text(motor_to_text(TEST_MOTOR))
    catalog = MotorCatalog(builtin, tmp_path / "user")
    assert catalog.get("test-motor-1").builtin
    with pytest.raises(ProjectExists, match="built-in"):
        catalog.add(TEST_MOTOR, replace_existing=True)
    with pytest.raises(ValidationError, match="built in and cannot be removed"):
        catalog.remove("TEST-MOTOR-1")
    assert (builtin / "TEST-MOTOR-1.toml").is_file()


def test_malformed_motor_file_names_file_and_line():
    text = '[motor]\nreference = "M"\n\n[motor_data]\npole_pairs = "four"\n'
    with pytest.raises(FileFormatError) as caught:
        motor_from_text(text, "M.toml")
    assert (caught.value.line, caught.value.reason) == (5, "motor data 'pole_pairs' must be an integer")


def test_a_malformed_catalog_file_is_named_by_its_place_in_the_catalog(tmp_path: Path):
    user = tmp_path / "store" / ".motors"
    user.mkdir(parents=True)
    (user / "M.toml").write_text('[motor]\nreference = "M"\n\n[motor_data]\npole_pairs = "four"\n')
    with pytest.raises(FileFormatError) as caught:
        MotorCatalog(tmp_path / "builtin", user).motors()
    assert str(caught.value) == "user motors/M.toml:5: motor data 'pole_pairs' must be an integer"


def test_shipped_catalog_files_load():
    for path in sorted(BUILTIN_MOTORS_DIR.glob("*.toml")):
        assert motor_from_text(path.read_text(), path, builtin=True).reference == path.stem


def test_selecting_a_motor_sets_motor_data_and_its_consequences(catalog: MotorCatalog, sim_project: ProjectService):
    sim_project.store.add_axis("p", Axis("X", "xtrapulspac", 1, "sim"))
    choice = sim_project.select_motor("p", "X", "TEST-MOTOR-1")
    values = {row.variable.key: row.value for row in choice.change.rows}
    assert values[(0x6410, 7)] == 4500 and values[(0x6080, 0)] == 4500
    assert values[(0x6410, 13)] == 85 and values[(0x340F, 0)] == 85
    assert (values[(0x3410, 1)], values[(0x3410, 2)], values[(0x3410, 3)]) == (4, 0x5555, 1200)
    assert values[(0x6402, 0)] == 0
    assert values[(0x3324, 1)] == -1
    assert (values[(0x6075, 0)], values[(0x6073, 0)]) == (2500, 3000)
    assert any("0x6510,1/2" in note for note in choice.notes)
    assert choice.snapshot.project.axis("X").motor == "TEST-MOTOR-1"
    row, _ = sim_project.parameters.get("p", "X", "0x6080")
    assert (row.value, row.file) == (4500, "DRIVEPAR.TXT")


def test_a_refused_motor_value_selects_nothing(catalog: MotorCatalog, sim_project: ProjectService):
    sim_project.store.add_axis("p", Axis("X", "xtrapulspac", 1, "sim"))
    bad = Motor("BAD", motor_data={"max_speed": 3000, "pole_pairs": 30})
    catalog.add(bad)
    before = sim_project.store.open("p")
    with pytest.raises(ParameterRefused, match=r"0x6410,14 .* 30 is outside 1..24"):
        sim_project.select_motor("p", "X", "BAD")
    assert sim_project.store.open("p") == before


@pytest.mark.parametrize("device", ["cd1k", "encotrive"])
def test_other_devices_refuse_catalog_motors(catalog: MotorCatalog, sim_project: ProjectService, device: str):
    """The CD1-k's 0x6410 holds other data: writing catalog fields there would be wrong."""
    sim_project.store.add_axis("p", Axis("E", device, 10, "sim"))
    with pytest.raises(ParameterRefused, match=f"device '{device}' does not take catalog motors"):
        sim_project.select_motor("p", "E", "TEST-MOTOR-1")


@pytest.mark.parametrize(
    ("stall", "peak", "drive_max", "drive_rated", "expected"),
    [
        (2500, 7500, 0, 0, (2500, 3000)),
        (2500, 7500, 6000, 2000, (2000, 3000)),
        (2500, 100_000, 0, 0, (2500, 32767)),
        (0, 7500, 0, 0, (0, 0)),
    ],
)
def test_current_limit_rule_matches_the_simulated_drive(stall, peak, drive_max, drive_rated, expected):
    assert current_limits(stall, peak, drive_max, drive_rated) == expected


@settings(deadline=None)
@given(*(st.integers(0, 200_000) for _ in range(4)))
def test_current_limit_rule_is_the_simulators(stall, peak, drive_max, drive_rated):
    """Tool and simulated drive must agree on what selecting a motor does to 0x6075/0x6073."""
    from servostudio.sim.drive.commissioning import current_limits as simulated

    assert current_limits(stall, peak, drive_max, drive_rated) == simulated(stall, peak, drive_max, drive_rated)
