"""The line-tracking INI reader and the EDS value syntax (numbers, $NODEID, REAL bit patterns)."""

from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from servostudio.od import DataType, DictionaryError
from servostudio.od.eds_values import ValueSyntaxError, float_bit_pattern, parse_integer, parse_value
from servostudio.od.ini import format_ini, parse_ini

SAFE_CHARS = st.characters(blacklist_categories=("Cs", "Cc", "Zl", "Zp"), blacklist_characters="\x85\x1c\x1d\x1e")
ASCII = st.characters(min_codepoint=0x20, max_codepoint=0x7E)  # CiA 306 keys and section names are ASCII
keys = (
    st.text(ASCII, min_size=1, max_size=12)
    .map(str.strip)
    .filter(lambda k: k and "=" not in k and ";" not in k and not k.startswith("["))
)
values = st.text(SAFE_CHARS, max_size=20).map(str.strip).filter(lambda v: ";" not in v)
names = (
    st.text(ASCII, min_size=1, max_size=12)
    .map(str.strip)
    .filter(lambda n: n and "[" not in n and "]" not in n and ";" not in n)
)


@st.composite
def ini_documents(draw: st.DrawFn) -> list[tuple[str, list[tuple[str, str]]]]:
    section_names = draw(st.lists(names, max_size=5, unique_by=str.casefold))
    document = []
    for name in section_names:
        entry_keys = draw(st.lists(keys, max_size=5, unique_by=str.casefold))
        document.append((name, [(key, draw(values)) for key in entry_keys]))
    return document


@given(ini_documents())
def test_format_then_parse_gives_back_sections_keys_values_and_lines(document) -> None:
    text = format_ini(document)
    ini = parse_ini(text, Path("doc.ini"))
    lines = text.splitlines()
    assert [section.name for section in ini] == [name for name, _ in document]
    for (name, entries), section in zip(document, ini, strict=True):
        assert lines[section.line - 1] == f"[{name}]"
        assert [(entry.key, entry.value) for entry in section] == entries
        for key, value in entries:
            assert section.get(key.upper()) == value  # keys are case-insensitive
            assert lines[section.line_of(key) - 1] == f"{key}={value}"


def test_comments_blank_lines_and_whitespace() -> None:
    text = "; header\n\n[Sec]\n  Key = some value ; trailing comment\nurl=a;b\n;Key2=x\n"
    ini = parse_ini(text, Path("c.ini"))
    section = ini.section("sec")
    assert section.line == 3
    assert section.get("KEY") == "some value" and section.line_of("key") == 4
    assert section.get("url") == "a;b"
    assert "Key2" not in section
    assert section.line_of("missing") == 3


@pytest.mark.parametrize(
    ("text", "line", "reason"),
    [
        ("key=1\n[S]\n", 1, "before any [section]"),
        ("[S]\nno equals sign\n", 2, "[S] expected 'key=value'"),
        ("[S]\n=value\n", 2, "expected 'key=value'"),
        ("[S\nk=v\n", 1, "malformed section header"),
        ("[S]\nk=1\nK=2\n", 3, "duplicate key"),
        ("[S]\n[s]\n", 2, "duplicate section"),
    ],
)
def test_malformed_ini_is_rejected_with_its_line(text: str, line: int, reason: str) -> None:
    with pytest.raises(DictionaryError) as caught:
        parse_ini(text, Path("bad.ini"))
    assert caught.value.line == line and reason in str(caught.value)
    assert str(caught.value).startswith(f"bad.ini:{line}: ")


@given(st.integers(-(2**64), 2**64), st.sampled_from(["{:d}", "0x{:X}", "0x{:x}", "0{:o}"]))
def test_integers_in_decimal_hex_and_octal(number: int, style: str) -> None:
    text = ("-" if number < 0 else "") + style.format(abs(number))
    if style == "0{:o}" and abs(number) == 0:
        text = "0"
    assert parse_integer(text) == number


@pytest.mark.parametrize("text", ["", "x", "0x", "08", "1.5", "- 3x", "$NODEID"])
def test_non_integers_are_refused(text: str) -> None:
    with pytest.raises(ValueSyntaxError):
        parse_integer(text)


@pytest.mark.parametrize(
    ("text", "constant"),
    [("$NODEID", 0), ("$NODEID+0x180", 0x180), ("$nodeid + 384", 384), ("0x180+$NODEID", 0x180)],
)
def test_nodeid_expressions_keep_the_constant_part(text: str, constant: int) -> None:
    assert parse_value(DataType.UNSIGNED32, text, allow_node_id=True) == (constant, True)


def test_nodeid_is_refused_where_not_allowed() -> None:
    with pytest.raises(ValueSyntaxError, match="NODEID"):
        parse_value(DataType.UNSIGNED32, "$NODEID+1", allow_node_id=False)


@given(st.floats(width=32, allow_nan=False))
def test_real32_values_as_bit_patterns_or_decimals(value: float) -> None:
    pattern = float_bit_pattern(DataType.REAL32, value)
    assert parse_value(DataType.REAL32, pattern) == (value, False)
    assert parse_value(DataType.REAL64, repr(value)) == (value, False)


def test_strings_and_octets() -> None:
    assert parse_value(DataType.VISIBLE_STRING, "XtrapulsPac 2") == ("XtrapulsPac 2", False)
    assert parse_value(DataType.OCTET_STRING, "01 02ab") == (b"\x01\x02\xab", False)
    with pytest.raises(ValueSyntaxError):
        parse_value(DataType.DOMAIN, "0g")
