"""A corpus of EDS/DCF files from other tools (tests/od/corpus/, licences in its README.md) and the built-in ones:
each passes lely's dcfchk, loads, and agrees with python ``canopen.import_od`` entry by entry (names, types, access,
defaults, limits, PDO flags, configured values).

Where canopen follows a convention of its own, lely's dcf-tools (the reference of CiA 306 the loader follows) is the
peer instead: CompactSubObj entries (canopen names them "Number of entries" / "name_2" and makes sub-index 0
writable), TIME values (canopen reads "365 43200000" as one number) and empty [DeviceInfo] numbers (canopen 2.4
stops on them, dcfchk accepts them).
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import canopen
import dcf
import pytest
from tests.od.peers import (
    NODE,
    as_dcf_tools_value,
    canopen_configured,
    canopen_copy,
    canopen_entry,
    canopen_view,
    compact_indices,
    our_view,
)

from servostudio.od import load_dictionary

REPO = Path(__file__).resolve().parents[2]
CORPUS = sorted((REPO / "tests" / "od" / "corpus").glob("*.[ed][dc][sf]")) + sorted((REPO / "eds").glob("*.eds"))
DCFCHK = Path(sys.executable).parent / "dcfchk"


def test_the_corpus_has_files_of_other_tools() -> None:
    names = {path.name for path in CORPUS}
    assert "lely-dcfgen-master.dcf" in names and "servostudio-generated-profile.eds" in names
    assert len(CORPUS) >= 8


@pytest.mark.parametrize("path", CORPUS, ids=[path.name for path in CORPUS])
def test_dcfchk_accepts_the_file(path: Path) -> None:
    result = subprocess.run([str(DCFCHK), "-n", str(NODE), str(path)], capture_output=True, text=True, timeout=60)
    assert (result.returncode, result.stderr) == (0, "")


@pytest.mark.parametrize("path", CORPUS, ids=[path.name for path in CORPUS])
def test_canopen_reads_the_same_entries(path: Path, tmp_path: Path) -> None:
    ours = load_dictionary(path)
    theirs = canopen.import_od(str(canopen_copy(path, tmp_path)), node_id=NODE)
    compact = compact_indices(path)
    compared = 0
    for variable in ours.variables():
        if variable.index in compact:
            continue
        entry = canopen_entry(theirs, variable)
        assert our_view(variable) == canopen_view(entry), variable.label
        if not variable.data_type.is_time:
            assert variable.default_for(NODE) == entry.default, variable.label
            assert variable.parameter_value_for(NODE) == canopen_configured(entry), variable.label
        compared += 1
    assert compared > 0


@pytest.mark.parametrize("path", CORPUS, ids=[path.name for path in CORPUS])
def test_dcf_tools_reads_the_same_compact_and_time_entries(path: Path) -> None:
    ours = load_dictionary(path)
    device = dcf.Device(dcf.parse_file(str(path)), {"NODEID": NODE})
    compact = compact_indices(path)
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
        assert as_dcf_tools_value(variable, expected) == entry.parse_value(), variable.label
