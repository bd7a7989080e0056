"""EDS/DCF files of open CiA 301/401/402 projects (tests/od/corpus/public/; source, commit and licence of each in
its SOURCES.md, the licence texts beside): every file lely's dcfchk accepts loads and agrees entry by entry with
python ``canopen.import_od`` (names, types, access, defaults, limits, PDO flags, configured values), with lely's
dcf-tools as the peer where canopen follows a convention of its own (CompactSubObj, TIME "days ms", REAL values as
bit patterns, files canopen cannot read); a file dcfchk refuses is refused with its place and reason, or loaded
where the loader is more lenient, never with a crash (issue 14, points 17-21)."""

from __future__ import annotations

import configparser
import re
from pathlib import Path

import canopen
import dcf
import pytest
from tests.od.peers import (
    NODE,
    canopen_configured,
    canopen_copy,
    canopen_entry,
    canopen_view,
    compact_indices,
    dcf_tools_view,
    dcfchk_verdict,
    our_dcf_tools_view,
    our_view,
)

from servostudio.od import DictionaryError, Variable, load_dictionary

PUBLIC = Path(__file__).resolve().parent / "corpus" / "public"
_ROW = re.compile(
    r"^\| `(?P<file>[^`]+)` \| \[(?P<repo>[^\]]+)\]\([^)]*\) @ `(?P<commit>[0-9a-f]+)` \| `[^`]+` \| "
    r"(?P<licence>[A-Za-z0-9.-]+) \| `LICENSES/(?P<text>[^`]+)` \| (?P<dcfchk>accepts|refuses) \|$",
    re.M,
)
SOURCES = {row["file"]: row.groupdict() for row in _ROW.finditer((PUBLIC / "SOURCES.md").read_text(encoding="utf-8"))}
FILES = sorted(path for path in PUBLIC.iterdir() if path.suffix.lower() in (".eds", ".dcf"))
#: licences that let the project redistribute a file (with the licence's text, which LICENSES/ holds)
REDISTRIBUTABLE = {"Apache-2.0", "MIT", "BSD-3-Clause"}


def _recorded(verdict: str) -> list[Path]:
    return [path for path in FILES if SOURCES.get(path.name, {}).get("dcfchk") == verdict]


def test_every_file_names_its_source_and_a_licence_that_lets_it_be_redistributed() -> None:
    assert len(FILES) >= 36
    assert set(SOURCES) == {path.name for path in FILES}
    for name, row in SOURCES.items():
        assert row["licence"] in REDISTRIBUTABLE, name
        assert (PUBLIC / "LICENSES" / row["text"]).is_file(), name
    assert len({row["repo"] for row in SOURCES.values()}) >= 8


@pytest.mark.parametrize("path", FILES, ids=[path.name for path in FILES])
def test_dcfchk_gives_the_recorded_verdict(path: Path) -> None:
    assert dcfchk_verdict(path) == SOURCES[path.name]["dcfchk"]


@pytest.mark.parametrize("path", _recorded("accepts"), ids=[path.name for path in _recorded("accepts")])
def test_what_dcfchk_accepts_loads_and_agrees_with_canopen_and_dcf_tools(path: Path, tmp_path: Path) -> None:
    ours = load_dictionary(path)
    theirs = _canopen(path, tmp_path)
    device = dcf.Device(dcf.parse_file(str(path)), {"NODEID": NODE})
    compact = compact_indices(path)
    by_canopen = 0
    for variable in ours.variables():
        if theirs is None or variable.index in compact or variable.data_type.is_time or variable.data_type.is_float:
            entry = device[variable.index][variable.subindex]
            assert our_dcf_tools_view(variable) == dcf_tools_view(entry), variable.label
        else:
            _agrees_with_canopen(variable, canopen_entry(theirs, variable))
            by_canopen += 1
    assert by_canopen > 0 or theirs is None


def _canopen(path: Path, tmp_path: Path) -> canopen.ObjectDictionary | None:
    """canopen's reading, or None for a file it cannot read (lely's ``[DummyUsage]`` without ``Dummy0001`` keys)."""
    try:
        return canopen.import_od(str(canopen_copy(path, tmp_path)), node_id=NODE)
    except (configparser.Error, ValueError, KeyError):  # canopen's limit: dcf-tools is the peer for the file
        return None


def _agrees_with_canopen(variable: Variable, entry) -> None:
    assert our_view(variable) == canopen_view(entry), variable.label
    assert variable.default_for(NODE) == entry.default, variable.label
    assert variable.parameter_value_for(NODE) == canopen_configured(entry), variable.label


@pytest.mark.parametrize("path", _recorded("refuses"), ids=[path.name for path in _recorded("refuses")])
def test_what_dcfchk_refuses_is_refused_with_its_place_or_loaded(path: Path) -> None:
    try:
        od = load_dictionary(path)
    except DictionaryError as error:
        assert (error.file, error.line >= 1, bool(error.section), bool(error.reason)) == (str(path), True, True, True)
        assert str(error).startswith(f"{path}:{error.line}: [{error.section}] ")
    else:
        assert len(od) > 0  # more lenient than dcfchk (decimal REAL values, "0x80+$NODEID"), and whole
