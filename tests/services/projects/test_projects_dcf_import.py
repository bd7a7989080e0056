"""DCF import into a project axis: a DCF's configured values (ParameterValue) become the axis's offline values,
checked like any offline edit; what the project cannot hold is listed; a DCF of another device is refused."""

from __future__ import annotations

from pathlib import Path

import pytest

from servostudio.od import DictionaryError, load_dictionary
from servostudio.services.projects import Axis, ParameterRefused, ProjectService

EDS = Path(__file__).resolve().parents[3] / "eds"


def _configure(text: str, section: str, value: str) -> str:
    """The text with ``ParameterValue=value`` as the first key of ``[section]``."""
    header = f"[{section}]\n"
    assert header in text, section
    return text.replace(header, f"{header}ParameterValue={value}\n", 1)


@pytest.fixture
def axes(sim_project: ProjectService) -> ProjectService:
    sim_project.store.add_axis("p", Axis("X", "xtrapulspac", 3, "sim"))
    sim_project.store.add_axis("p", Axis("Y", "xtrapulspac", 4, "sim"))
    return sim_project


def _row(service: ProjectService, axis: str, address: str):
    return service.parameters.get("p", axis, address)[0]


def test_a_dcfs_configured_values_become_the_axis_values(axes: ProjectService, tmp_path: Path) -> None:
    text = (EDS / "xtrapulspac.eds").read_text(encoding="latin-1")
    text = _configure(_configure(text, "1400sub2", "1"), "1600sub2", "0x60FF0020")
    text = _configure(text, "1400sub1", "$NODEID+0x300")
    dcf = tmp_path / "line.dcf"
    dcf.write_text(_configure(text, "6041", "7"), encoding="latin-1")
    shown = load_dictionary(dcf)
    assert (shown[0x1400, 2].default, shown[0x1400, 2].parameter_value) == (255, 1)  # shown as configured

    imported = axes.import_dcf("p", "Y", dcf.read_text(encoding="latin-1"), dcf.name)
    assert {(row.variable.index, row.variable.subindex): row.value for row in imported.change.rows} == {
        (0x1400, 1): 0x304,  # $NODEID resolved for the axis (node 4)
        (0x1400, 2): 1,
        (0x1600, 2): 0x60FF0020,
    }
    assert [reason for reason in imported.skipped if "0x6041" in reason] == [imported.skipped[0]]
    assert "read-only" in imported.skipped[0]
    assert (_row(axes, "Y", "0x1600,2").value, _row(axes, "Y", "0x1600,2").file) == (0x60FF0020, "USER_PAR.TXT")


def test_export_then_import_gives_the_same_values(axes: ProjectService, tmp_path: Path) -> None:
    axes.parameters.set("p", "X", {"0x6060": -3, "0x3050,1": 0x60FD0003, "0x2004": "Lift axis", "0x1006": 20000})
    dcf = tmp_path / "X.dcf"
    dcf.write_text(axes.dcf("p", "X"), encoding="latin-1", newline="")
    imported = axes.import_dcf("p", "Y", dcf.read_text(encoding="latin-1"), dcf.name)
    assert imported.skipped == []
    for address, value in (("0x6060", -3), ("0x3050,1", 0x60FD0003), ("0x2004", "Lift axis"), ("0x1006", 20000)):
        assert _row(axes, "Y", address).value == value, address


def test_an_out_of_range_configured_value_changes_nothing(axes: ProjectService, tmp_path: Path) -> None:
    text = (EDS / "xtrapulspac.eds").read_text(encoding="latin-1")
    dcf = tmp_path / "bad.dcf"
    dcf.write_text(_configure(_configure(text, "1400sub2", "1"), "3410sub1", "25"), encoding="latin-1")
    with pytest.raises(DictionaryError, match="ParameterValue 25 is outside the limits") as refused:
        axes.import_dcf("p", "Y", dcf.read_text(encoding="latin-1"), dcf.name)
    assert _row(axes, "Y", "0x1400,2").file is None
    assert str(refused.value).startswith("bad.dcf:") and str(tmp_path) not in str(refused.value)  # no server path


def test_a_dcf_of_another_device_is_refused(axes: ProjectService, tmp_path: Path) -> None:
    dcf = tmp_path / "cd1k.dcf"
    dcf.write_text(_configure((EDS / "cd1k.eds").read_text(encoding="latin-1"), "6060", "1"), encoding="latin-1")
    with pytest.raises(ParameterRefused, match="the axis is a xtrapulspac"):
        axes.import_dcf("p", "Y", dcf.read_text(encoding="latin-1"), dcf.name)
