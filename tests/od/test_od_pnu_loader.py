"""The `.pnu` parameter-list loader: precise `FILE:LINE: [SECTION] REASON` errors, a round trip of any
parameter list through its text, and no crash (only precise errors) on mutated files."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from servostudio.od import DictionaryError
from servostudio.od.library import BUILTIN_EDS_DIR
from servostudio.od.pnu import parse_parameter_list

PATH = Path("test.pnu")
VALID = """\
[Device]
Name=Test drive
IdentNumber=0x1234

[PNU700]
Name=Pole pairs
Type=U16
Access=rw
Min=1
Max=32
Default=4
Save=E
Reference=L900

[PNU828]
Name=Mapping
Type=U16
Access=rw
Index=0..2
Default=1, 2, 3
Enum.1=one
Bit.0=low
Bits.8-15=high
"""


def load(text: str):
    return parse_parameter_list(text, PATH)


def test_the_valid_file_loads() -> None:
    dictionary = load(VALID)
    assert dictionary.ident_number == 0x1234 and dictionary[828, 2].default == 3
    assert [bit.name for bit in dictionary[828, 0].bits] == ["low", "high"]


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        ("IdentNumber=0x1234", "IdentNumber=0x12345", "test.pnu:3: [Device] IdentNumber 74565 is outside 0..65535"),
        ("Name=Test drive", "Nmae=Test drive", "test.pnu:2: [Device] unknown key 'Nmae'"),
        ("[PNU700]", "[PNU2000]", "test.pnu:5: [PNU2000] PNU 2000 is outside 1..1999"),
        ("[PNU700]", "[Parameter700]", "test.pnu:5: [Parameter700] section must be [Device] or [PNU<n>]"),
        ("Name=Pole pairs", "Title=Pole pairs", "test.pnu:6: [PNU700] unknown key 'Title'"),
        ("Type=U16", "Type=word", "test.pnu:7: [PNU700] Type 'word' is not one of U16, I16, U32, I32"),
        ("Access=rw", "Access=const", "test.pnu:8: [PNU700] Access 'const' is not one of ro, rw, wo"),
        ("Min=1", "Min=40", "test.pnu:10: [PNU700] Max 32 is below Min 40"),
        ("Max=32", "Max=70000", "test.pnu:10: [PNU700] Max 70000 is outside 0..65535"),
        ("Default=4", "Default=33", "test.pnu:11: [PNU700] Default 33 is outside 1..32"),
        ("Default=4", "Default=four", "test.pnu:11: [PNU700] Default: 'four' is not an integer"),
        ("Save=E", "Save=EEPROM", "test.pnu:12: [PNU700] Save 'EEPROM' is not one of E, S, RAM"),
        ("Default=1, 2, 3", "Default=1, 2", "test.pnu:20: [PNU828] Default gives 2 values for 3 indices"),
        ("Index=0..2", "Index=2..0", "test.pnu:19: [PNU828] Index 2..0 must be ascending within 0..255"),
        ("Index=0..2", "Index=0-2", "test.pnu:19: [PNU828] Index '0-2' must be FIRST..LAST"),
        ("Bits.8-15=high", "Bits.8-16=high", "test.pnu:23: [PNU828] bits 8..16 do not fit 16 bits"),
        ("Bits.8-15=high", "Bits.0-3=high", "test.pnu:23: [PNU828] bits 0..3 overlap 'low'"),
        ("Enum.1=one", "Enum.-1=one", "test.pnu:21: [PNU828] Enum value -1 is outside 0..65535"),
        ("Name=Mapping\n", "", "test.pnu:15: [PNU828] Name is missing"),
        ("Save=E", "Save=E\nRepeatable=yes", "test.pnu:13: [PNU700] Repeatable=yes needs Procedure=yes"),
        ("Save=E", "Save=E\nProcedure=yes\nRepeatable=1", "test.pnu:14: [PNU700] Repeatable must be yes or no"),
    ],
)
def test_each_broken_rule_names_file_line_section_and_reason(old: str, new: str, message: str) -> None:
    assert old in VALID
    with pytest.raises(DictionaryError) as error:
        load(VALID.replace(old, new, 1))
    assert str(error.value).startswith(message), str(error.value)


def test_a_file_without_a_device_section_is_refused() -> None:
    with pytest.raises(DictionaryError, match=r"^test\.pnu:1: \[Device\] section \[Device\] is missing$"):
        load(VALID.split("[PNU700]")[1].join(("[PNU700]", "")))


# -- round trip -----------------------------------------------------------------------------------------------

TYPES = {"U16": (0, 0xFFFF), "I16": (-(2**15), 2**15 - 1), "U32": (0, 2**32 - 1), "I32": (-(2**31), 2**31 - 1)}
texts = st.text(st.characters(codec="ascii", categories=("L", "N", "Zs", "Pd")), min_size=1, max_size=30).map(str.strip)


@st.composite
def parameters(draw, pnu: int) -> dict:
    kind = draw(st.sampled_from(sorted(TYPES)))
    low, high = sorted(draw(st.lists(st.integers(*TYPES[kind]), min_size=2, max_size=2)))
    indices = draw(st.none() | st.integers(1, 4))
    count = indices or 1
    procedure = draw(st.booleans())
    return {
        "pnu": pnu,
        "Name": draw(texts.filter(bool)),
        "Type": kind,
        "Access": draw(st.sampled_from(["ro", "rw", "wo"])),
        "Min": low,
        "Max": high,
        "Default": draw(st.lists(st.integers(low, high), min_size=count, max_size=count)),
        "Save": draw(st.sampled_from(["E", "S", "RAM"])),
        "Index": indices,
        "Group": draw(texts),
        "Unit": draw(texts),
        "Derived": draw(texts),
        "Procedure": procedure,
        "Repeatable": procedure and draw(st.booleans()),
    }


def render(device: int, specs: list[dict]) -> str:
    lines = ["[Device]", f"IdentNumber={device}"]
    for spec in specs:
        lines += ["", f"[PNU{spec['pnu']}]"]
        for key in ("Name", "Type", "Access", "Min", "Max", "Save", "Group", "Unit", "Derived"):
            lines.append(f"{key}={spec[key]}")
        lines.append("Default=" + ", ".join(str(value) for value in spec["Default"]))
        if spec["Index"]:
            lines.append(f"Index=0..{spec['Index'] - 1}")
        lines += [f"{flag}=yes" for flag in ("Procedure", "Repeatable") if spec[flag]]
    return "\n".join(lines) + "\n"


@st.composite
def parameter_lists(draw) -> tuple[int, list[dict]]:
    pnus = draw(st.lists(st.integers(1, 1999), min_size=1, max_size=6, unique=True))
    return draw(st.integers(0, 0xFFFF)), [draw(parameters(pnu)) for pnu in pnus]


@given(parameter_lists())
def test_any_parameter_list_reads_back_from_its_text(drawn: tuple[int, list[dict]]) -> None:
    ident, specs = drawn
    dictionary = load(render(ident, specs))
    assert dictionary.ident_number == ident
    for spec in specs:
        parameter = dictionary.parameters[spec["pnu"]]
        assert (parameter.name, parameter.data_type.name[0], parameter.access.value) == (
            spec["Name"],
            spec["Type"][0],
            spec["Access"],
        )
        assert (parameter.low, parameter.high, parameter.persistence.value) == (spec["Min"], spec["Max"], spec["Save"])
        assert [parameter.default_at(index) for index in parameter.index_range] == spec["Default"]
        assert (parameter.group, parameter.unit, parameter.derived) == (spec["Group"], spec["Unit"], spec["Derived"])
        assert len(parameter.index_range) == (spec["Index"] or 1)
        assert (parameter.procedure, parameter.repeatable) == (spec["Procedure"], spec["Repeatable"])


# -- mutated files --------------------------------------------------------------------------------------------

BUILTIN = (BUILTIN_EDS_DIR / "ttapro.pnu").read_text(encoding="utf-8").splitlines()
GARBAGE = st.sampled_from(["", "x", "=", "[", "[PNU]", "Min=", "Max=-1", "Type=U64", "Default=0x", "Index=9..1", "é"])


@settings(max_examples=60, deadline=None)
@given(
    st.lists(
        st.tuples(st.integers(0, len(BUILTIN) - 1), st.sampled_from(["drop", "replace", "append"]), GARBAGE), max_size=3
    )
)
def test_a_mutated_list_loads_or_names_the_line_that_breaks_it(mutations) -> None:
    lines = list(BUILTIN)
    for position, action, garbage in mutations:
        position = min(position, len(lines) - 1)
        if action == "drop":
            del lines[position]
        elif action == "replace":
            lines[position] = garbage
        else:
            lines[position] += garbage
    try:
        load("\n".join(lines) + "\n")
    except DictionaryError as error:
        match = re.match(r"^test\.pnu:(\d+): \[[^\]]*\] .+", str(error))
        assert match, str(error)
        assert 1 <= int(match[1]) <= len(lines)
