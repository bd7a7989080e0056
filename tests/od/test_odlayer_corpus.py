"""A corpus of EDS/DCF files from other tools (tests/od/corpus/, licences in its README.md) and the built-in ones:
each passes lely's dcfchk, loads, and agrees with python ``canopen.import_od`` entry by entry (names, types, access,
defaults, limits, PDO flags, configured values).

Where canopen follows a convention of its own, lely's dcf-tools (the reference of CiA 306 the loader follows) is the
peer instead: CompactSubObj entries (canopen names them "Number of entries" / "name_2" and makes sub-index 0
writable), TIME values (canopen reads "365 43200000" as one number) and empty [DeviceInfo] numbers (canopen 2.4
stops on them, dcfchk accepts them).
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import canopen
import dcf
import pytest
from canopen.objectdictionary import ODVariable

from servostudio.od import Variable, load_dictionary
from servostudio.od.ini import read_ini

REPO = Path(__file__).resolve().parents[2]
CORPUS = sorted((REPO / "tests" / "od" / "corpus").glob("*.[ed][dc][sf]")) + sorted((REPO / "eds").glob("*.eds"))
DCFCHK = Path(sys.executable).parent / "dcfchk"
NODE = 5


def test_the_corpus_has_files_of_other_tools() -> None:
    names = {path.name for path in CORPUS}
    assert "lely-dcfgen-master.dcf" in names and "servostudio-generated-profile.eds" in names
    assert len(CORPUS) >= 8


@pytest.mark.parametrize("path", CORPUS, ids=[path.name for path in CORPUS])
def test_dcfchk_accepts_the_file(path: Path) -> None:
    result = subprocess.run([str(DCFCHK), "-n", str(NODE), str(path)], capture_output=True, text=True, timeout=60)
    assert (result.returncode, result.stderr) == (0, "")


def _canopen_copy(path: Path, tmp_path: Path) -> Path:
    """The file as canopen 2.4 can read it: without empty [DeviceInfo] numbers (it stops on them)."""
    text = re.sub(
        r"^(VendorNumber|ProductNumber|RevisionNumber)=\s*$\n", "", path.read_text(encoding="latin-1"), flags=re.M
    )
    copy = tmp_path / path.name
    copy.write_text(text, encoding="latin-1")
    return copy


def _compact_indices(path: Path) -> set[int]:
    """The objects the file writes with CompactSubObj."""
    ini = read_ini(path)
    return {int(section.name, 16) for section in ini if len(section.name) == 4 and section.get("CompactSubObj")}


def _canopen_entry(theirs: canopen.ObjectDictionary, variable: Variable) -> ODVariable:
    entry = theirs[variable.index]
    return entry if isinstance(entry, ODVariable) else entry[variable.subindex]


def _canopen_view(entry: ODVariable) -> tuple:
    return (entry.name, entry.data_type, entry.access_type, entry.pdo_mappable, entry.min, entry.max)


def _our_view(variable: Variable) -> tuple:
    access = variable.access.value
    return (variable.name, int(variable.data_type), access, variable.pdo_mappable, variable.low, variable.high)


@pytest.mark.parametrize("path", CORPUS, ids=[path.name for path in CORPUS])
def test_canopen_reads_the_same_entries(path: Path, tmp_path: Path) -> None:
    ours = load_dictionary(path)
    theirs = canopen.import_od(str(_canopen_copy(path, tmp_path)), node_id=NODE)
    compact = _compact_indices(path)
    compared = 0
    for variable in ours.variables():
        if variable.index in compact:
            continue
        entry = _canopen_entry(theirs, variable)
        assert _our_view(variable) == _canopen_view(entry), variable.label
        if not variable.data_type.is_time:
            assert variable.default_for(NODE) == entry.default, variable.label
            assert variable.parameter_value_for(NODE) == _canopen_configured(entry), variable.label
        compared += 1
    assert compared > 0


def _canopen_configured(entry: ODVariable) -> object:
    return entry.value if getattr(entry, "value_raw", None) not in (None, "") else None


@pytest.mark.parametrize("path", CORPUS, ids=[path.name for path in CORPUS])
def test_dcf_tools_reads_the_same_compact_and_time_entries(path: Path) -> None:
    ours = load_dictionary(path)
    device = dcf.Device(dcf.parse_file(str(path)), {"NODEID": NODE})
    compact = _compact_indices(path)
    for variable in ours.variables():
        if not (variable.index in compact or variable.data_type.is_time):
            continue
        entry = device[variable.index][variable.subindex]
        assert (variable.name, variable.access.value, int(variable.data_type), variable.pdo_mappable) == (
            entry.name,
            entry.access_type.name,
            entry.data_type.index,
            entry.pdo_mapping,
        ), variable.label
        expected = variable.parameter_value_for(NODE)
        if expected is None:
            expected = variable.default_for(NODE) or 0
        assert _as_dcf_tools_value(variable, expected) == entry.parse_value(), variable.label


def _as_dcf_tools_value(variable: Variable, value: object) -> object:
    """dcf-tools keeps TIME values as (days, ms)."""
    if variable.data_type.is_time and isinstance(value, int):
        return (value >> 32, value & 0xFFFFFFFF)
    return value
