"""Device Config templates and DCF export."""

from __future__ import annotations

import configparser
import subprocess
from pathlib import Path

import pytest

from servostudio.services.projects import TEMPLATES, Axis, ProjectNotFound, ProjectService, templates_for

DCFCHK = Path(__file__).resolve().parents[3] / ".venv" / "bin" / "dcfchk"


@pytest.fixture
def axis(sim_project: ProjectService) -> ProjectService:
    sim_project.store.add_axis("p", Axis("X", "xtrapulspac", 3, "sim"))
    return sim_project


def test_template_settings_and_groups_exist_in_the_dictionary(service: ProjectService):
    dictionary = service.library.load("xtrapulspac")
    groups = {variable.group for variable in dictionary.variables()}
    for template in templates_for("xtrapulspac"):
        for setting in template.settings:
            variable = dictionary[setting.index, setting.sub]
            variable.check(setting.value)
        assert set(template.groups or ()) <= groups, template.key
    assert [t.key for t in TEMPLATES] == ["analog-speed", "positioner", "stepper-emulation", "expert"]


@pytest.mark.parametrize(("key", "mode"), [("analog-speed", -1), ("positioner", -3), ("stepper-emulation", -2)])
def test_a_template_sets_mode_and_io_and_is_recorded(axis: ProjectService, key: str, mode: int):
    choice = axis.apply_template("p", "X", key)
    row, _ = axis.parameters.get("p", "X", "0x6060")
    assert row.value == mode
    template = next(t for t in TEMPLATES if t.key == key)
    assert [(r.variable.index, r.variable.subindex, r.value) for r in choice.change.rows] == [
        (s.index, s.sub, s.value) for s in template.settings
    ]
    assert choice.snapshot.project.axis("X").application == key
    assert axis.application("p", "X") == template


def test_expert_mode_sets_nothing_and_shows_everything(axis: ProjectService):
    before = (axis.store.root / "p" / "X" / "DRIVEPAR.TXT").read_bytes()
    choice = axis.apply_template("p", "X", "expert")
    assert choice.change.rows == []
    assert (axis.store.root / "p" / "X" / "DRIVEPAR.TXT").read_bytes() == before
    assert axis.application("p", "X").groups is None


def test_templates_are_per_device(axis: ProjectService):
    axis.store.add_axis("p", Axis("C", "cd1k", 9, "sim"))
    with pytest.raises(ProjectNotFound, match="available: expert"):
        axis.apply_template("p", "C", "positioner")


def test_dcf_holds_commissioning_and_project_values_and_passes_dcfchk(axis: ProjectService, tmp_path: Path):
    axis.parameters.set("p", "X", {"0x6060": -3, "0x3050,1": 0x60FD0003, "0x2004": "Lift axis", "0x1006": 20000})
    path = tmp_path / "X.dcf"
    path.write_text(axis.dcf("p", "X"), encoding="latin-1", newline="")
    _dcfchk(path)
    dcf = configparser.ConfigParser(interpolation=None, strict=False)
    dcf.optionxform = str
    dcf.read(path, encoding="latin-1")
    assert dict(dcf["DeviceComissioning"]) == {
        "NodeID": "3",
        "NodeName": "X",
        "Baudrate": "1000",
        "NetNumber": "1",
        "NetworkName": "p",
        "CANopenManager": "0",
    }
    values = {section: dcf[section]["ParameterValue"] for section in dcf.sections() if "ParameterValue" in dcf[section]}
    assert values == {"6060": "-3", "3050sub1": "0x60FD0003", "2004": "Lift axis", "1006": "0x4E20"}


def test_dcf_of_the_eds_sections_is_unchanged_otherwise(axis: ProjectService):
    eds = axis.library.load("xtrapulspac").source.read_text(encoding="latin-1")
    dcf = axis.dcf("p", "X")
    assert dcf.startswith(eds.rstrip("\r\n"))


def _dcfchk(path: Path) -> None:
    """dcf-tools' checker must accept the file without a word (errors or warnings)."""
    result = subprocess.run([str(DCFCHK), str(path)], capture_output=True, text=True)
    assert (result.returncode, result.stdout, result.stderr) == (0, "", "")


@pytest.mark.parametrize(("device", "node"), [("cd1k", 127), ("encotrive", 112)])
def test_dcf_of_other_devices_passes_dcfchk(sim_project: ProjectService, tmp_path: Path, device: str, node: int):
    sim_project.store.add_axis("p", Axis("A", device, node, "sim"))
    rows, _ = sim_project.parameters.rows("p", "A")
    editable = [row.variable for row in rows if row.editable_reason is None and row.variable.data_type.is_integer]
    sim_project.parameters.set("p", "A", {f"0x{v.index:04X},{v.subindex}": v.minimum or 0 for v in editable[:5]})
    path = tmp_path / "A.dcf"
    path.write_text(sim_project.dcf("p", "A"), encoding="latin-1", newline="")
    _dcfchk(path)
    assert path.read_text(encoding="latin-1").count("ParameterValue=") == 5
