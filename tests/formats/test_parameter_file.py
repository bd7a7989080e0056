"""TTAPAR.TXT (docs/profibus.md §10): the object file's syntax with PNU,IND addresses — the canonical text, what
the reader refuses with its line, and round trips of any parameter set (hypothesis)."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from servostudio.formats.objectfile import ObjectEntry, ObjectFileError
from servostudio.formats.parameterfile import format_parameter_file, parse_parameter_file


def test_the_canonical_text_is_decimal_sorted_and_reads_back() -> None:
    entries = [ObjectEntry(828, 2, 0x2306), ObjectEntry(700, 0, 4), ObjectEntry(747, 0, -2147483648)]
    text = format_parameter_file(entries, header="TTAPAR.TXT of node 5")
    assert text == "; TTAPAR.TXT of node 5\n700,0=4\n747,0=-2147483648\n828,2=8966\n"
    assert parse_parameter_file(text) == sorted(entries, key=lambda entry: (entry.index, entry.sub))


def test_the_object_file_spellings_are_read_too() -> None:
    text = "; comment\n  700,0=1  ; indented: ignored\n0x2BC, 0 = 0x4 ; hex as in DRIVEPAR.TXT\nnot a line\n"
    assert parse_parameter_file(text) == [ObjectEntry(700, 0, 4)]


@pytest.mark.parametrize(
    ("text", "reason"),
    [
        ("2000,0=1\n", "2: PNU 2000 outside 1..1999"),
        ("0,0=1\n", "2: PNU 0 outside 1..1999"),
        ("795,256=1\n", "2: sub-index 256 out of range"),
        ("700,0=four\n", "2: value 'four' is not an integer"),
        ("700,0=4\n700,0=5\n", "3: duplicate assignment"),
        ("700=4\n", "2: expected 'index,sub' before '='"),
    ],
)
def test_a_bad_line_is_refused_with_its_number(text: str, reason: str) -> None:
    with pytest.raises(ObjectFileError, match=f"^TTAPAR.TXT:{reason}"):
        parse_parameter_file("; header\n" + text, "TTAPAR.TXT")


def test_the_validator_sees_only_entries_the_syntax_accepted() -> None:
    seen: list[ObjectEntry] = []

    def validate(entry: ObjectEntry) -> str | None:
        seen.append(entry)
        return "PNU 760: over the limit" if entry.index == 760 else None

    with pytest.raises(ObjectFileError, match=r"^F:2: PNU 760: over the limit$"):
        parse_parameter_file("700,0=4\n760,0=99999\n", "F", validate)
    assert [entry.index for entry in seen] == [700, 760]


def test_the_writer_refuses_what_the_reader_would() -> None:
    with pytest.raises(ValueError, match="PNU 700,0: value 'x' is not an integer"):
        format_parameter_file([ObjectEntry(700, 0, "x")])
    with pytest.raises(ValueError, match="assigned twice"):
        format_parameter_file([ObjectEntry(700, 0, 1), ObjectEntry(700, 0, 2)])


_ENTRIES = st.dictionaries(
    st.tuples(st.integers(1, 1999), st.integers(0, 255)), st.integers(-(2**31), 2**32 - 1), max_size=40
)


@given(_ENTRIES)
def test_any_parameter_set_reads_back_from_its_text(values: dict[tuple[int, int], int]) -> None:
    entries = [ObjectEntry(pnu, ind, value) for (pnu, ind), value in values.items()]
    text = format_parameter_file(entries, header="backup\nof a drive")
    assert parse_parameter_file(text) == sorted(entries, key=lambda entry: (entry.index, entry.sub))
    assert format_parameter_file(parse_parameter_file(text), header="backup\nof a drive") == text
