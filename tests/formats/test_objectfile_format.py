"""The object file (DRIVEPAR.TXT / USER_PAR.TXT): the manual's examples, every syntax rule, canonical writing."""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from servostudio.formats.objectfile import (
    ObjectEntry,
    ObjectFileError,
    format_object_file,
    parse_object_file,
    read_object_file,
    write_object_file,
)

FIXTURES = Path(__file__).parent / "fixtures"


def test_manual_examples_hex_and_decimal_mean_the_same_assignment() -> None:
    hex_form = read_object_file(FIXTURES / "manual_objectfile_hex.txt")
    decimal_form = read_object_file(FIXTURES / "manual_objectfile_decimal.txt")
    assert hex_form == decimal_form == [ObjectEntry(0x3549, 10, 0x12)]
    assert hex_form[0].line == 1


def test_manual_examples_together_are_a_duplicate(tmp_path: Path) -> None:
    both = tmp_path / "DRIVEPAR.TXT"
    both.write_text(
        (FIXTURES / "manual_objectfile_hex.txt").read_text() + (FIXTURES / "manual_objectfile_decimal.txt").read_text()
    )
    with pytest.raises(ObjectFileError) as caught:
        read_object_file(both)
    assert (caught.value.file, caught.value.line) == (str(both), 2)
    assert "duplicate" in caught.value.reason and "0x3549,10" in caught.value.reason
    assert "first at line 1" in caught.value.reason
    assert str(caught.value) == f"{both}:2: {caught.value.reason}"


def test_comments_and_lines_not_starting_with_a_digit_are_ignored() -> None:
    text = (
        "; saved by the drive\n"
        "0x6060,0=-3 ; trailing comment\n"
        "\n"
        "Axis parameters\n"
        "  0x6081,0=100\n"  # indented: does not begin with a digit, the drive skips it
        "-1,0=5\n"
        "x0x6083,0=1\n"
        "24705, 0=2000\r\n"
    )
    entries = parse_object_file(text, "USER_PAR.TXT")
    assert entries == [ObjectEntry(0x6060, 0, -3), ObjectEntry(0x6081, 0, 2000)]
    assert [entry.line for entry in entries] == [2, 8]


def test_values_are_numbers_or_raw_text() -> None:
    entries = parse_object_file("0x2004,0=Axis X\n0x3549,0xA=0XfF\n8196,1=+7\n0x6099,2=007\n")
    assert [entry.value for entry in entries] == ["Axis X", 255, 7, 7]


@pytest.mark.parametrize(
    ("line", "reason"),
    [
        ("0x3549=1", "exactly one comma"),
        ("0x3549,1,2=1", "exactly one comma"),
        ("0x3549,10", "no '='"),
        ("0x3549,10=", "missing value"),
        ("0x3549,10= ; nothing", "missing value"),
        ("0x35G9,10=1", "index '0x35G9' is not a decimal or 0x hex number"),
        ("0x3549,ten=1", "sub-index 'ten' is not a decimal or 0x hex number"),
        ("0x3549, =1", "sub-index '' is not"),
        ("0x13549,1=1", "index 0x13549 out of range 0..0xFFFF"),
        ("0x3549,256=1", "sub-index 256 out of range 0..0xFF"),
        ("0x3549,-1=1", "sub-index -1 out of range"),
        ("0x3549,1=0x", "value '0x' is not a decimal or 0x hex number"),
        ("0x3549,1=12abc", "value '12abc' is not"),
        ("0x3549,1=-0x1G", "value '-0x1G' is not"),
    ],
)
def test_malformed_lines_starting_with_a_digit_are_rejected(line: str, reason: str) -> None:
    text = "; header\n0x1000,0=1\n" + line + "\n0x1001,0=1\n"
    with pytest.raises(ObjectFileError) as caught:
        parse_object_file(text, "DRIVEPAR.TXT")
    error = caught.value
    assert (error.file, error.line) == ("DRIVEPAR.TXT", 3)
    assert reason in error.reason
    assert str(error).startswith("DRIVEPAR.TXT:3: ")


def test_validation_hook_rejects_with_the_line() -> None:
    def only_known(entry: ObjectEntry) -> str | None:
        return None if entry.index == 0x6060 else f"object 0x{entry.index:04X} is not in the dictionary"

    assert parse_object_file("0x6060,0=1\n", validate=only_known) == [ObjectEntry(0x6060, 0, 1)]
    with pytest.raises(ObjectFileError) as caught:
        parse_object_file("0x6060,0=1\n0x7000,1=1\n", "USER_PAR.TXT", validate=only_known)
    assert (caught.value.line, caught.value.reason) == (2, "object 0x7000 is not in the dictionary")


def test_writer_is_canonical_sorted_and_commented() -> None:
    entries = [
        ObjectEntry(0x6081, 0, 0x10),
        ObjectEntry(0x2004, 0, "Axis X"),
        ObjectEntry(0x3549, 10, -18),
        ObjectEntry(0x3549, 2, 5),
    ]
    assert format_object_file(entries, header="DRIVEPAR.TXT\n\nnode 3") == (
        "; DRIVEPAR.TXT\n;\n; node 3\n0x2004,0=Axis X\n0x3549,2=5\n0x3549,10=-18\n0x6081,0=16\n"
    )
    assert format_object_file([]) == ""


@pytest.mark.parametrize(
    ("entry", "reason"),
    [
        (ObjectEntry(0x10000, 0, 1), "out of range"),
        (ObjectEntry(0x1000, 256, 1), "out of range"),
        (ObjectEntry(0x2004, 0, "1st axis"), "starts like a number"),
        (ObjectEntry(0x2004, 0, "a;b"), "contains ';'"),
        (ObjectEntry(0x2004, 0, "a\nb"), "line break"),
        (ObjectEntry(0x2004, 0, " padded"), "leading/trailing spaces"),
        (ObjectEntry(0x2004, 0, ""), "empty"),
        (ObjectEntry(0x2004, 0, "axe \u2192"), "latin-1"),
    ],
)
def test_writer_refuses_entries_that_would_not_read_back(entry: ObjectEntry, reason: str) -> None:
    with pytest.raises(ValueError, match=reason):
        format_object_file([entry])


def test_writer_refuses_duplicates() -> None:
    with pytest.raises(ValueError, match="duplicate entry 0x1000,1"):
        format_object_file([ObjectEntry(0x1000, 1, 1), ObjectEntry(0x1000, 1, 2)])


def test_write_replaces_the_file_atomically(tmp_path: Path) -> None:
    target = tmp_path / "DRIVEPAR.TXT"
    target.write_text("old content\n")
    target.chmod(0o640)
    write_object_file(target, [ObjectEntry(0x6060, 0, 1)], header="saved")
    assert target.read_text() == "; saved\n0x6060,0=1\n"
    assert target.stat().st_mode & 0o777 == 0o640
    assert os.listdir(tmp_path) == ["DRIVEPAR.TXT"]
    assert read_object_file(target) == [ObjectEntry(0x6060, 0, 1)]


def test_failed_write_leaves_the_old_file_and_no_temporary(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    target = tmp_path / "DRIVEPAR.TXT"
    target.write_text("0x6060,0=1\n")

    def broken_replace(source: str, destination: str) -> None:
        raise OSError("disk full")

    monkeypatch.setattr(os, "replace", broken_replace)
    with pytest.raises(OSError, match="disk full"):
        write_object_file(target, [ObjectEntry(0x6060, 0, 2)])
    assert target.read_text() == "0x6060,0=1\n"
    assert os.listdir(tmp_path) == ["DRIVEPAR.TXT"]


def test_invalid_entries_never_touch_the_file(tmp_path: Path) -> None:
    target = tmp_path / "USER_PAR.TXT"
    target.write_text("0x6060,0=1\n")
    with pytest.raises(ValueError):
        write_object_file(target, [ObjectEntry(0x6060, 0, 2), ObjectEntry(0x2004, 0, "9 lives")])
    assert target.read_text() == "0x6060,0=1\n"
    assert os.listdir(tmp_path) == ["USER_PAR.TXT"]


# --- properties -------------------------------------------------------------------------------------------------

_TEXT_START = st.sampled_from("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ_#\u00e9\u00b0")
_TEXT_REST = st.text(alphabet=st.sampled_from("abcXYZ019 _-.,:=#\u00e9"), max_size=12)
_TEXT_VALUES = st.builds(lambda first, rest: (first + rest).rstrip() or first, _TEXT_START, _TEXT_REST)
_VALUES = st.one_of(st.integers(-(2**63), 2**64), _TEXT_VALUES)
_ENTRY_LISTS = st.dictionaries(st.tuples(st.integers(0, 0xFFFF), st.integers(0, 0xFF)), _VALUES, max_size=40).map(
    lambda mapping: [ObjectEntry(index, sub, value) for (index, sub), value in mapping.items()]
)


@settings(deadline=None)
@given(_ENTRY_LISTS, st.one_of(st.none(), st.text(max_size=40).filter(lambda text: text.isprintable())))
def test_round_trip_write_then_read(entries: list[ObjectEntry], header: str | None) -> None:
    text = format_object_file(entries, header)
    read_back = parse_object_file(text)
    assert read_back == sorted(entries, key=lambda entry: (entry.index, entry.sub))
    assert format_object_file(read_back, header) == text


@settings(deadline=None, max_examples=50)
@given(_ENTRY_LISTS, st.data())
def test_any_spelling_of_an_entry_reads_the_same(entries: list[ObjectEntry], data: st.DataObject) -> None:
    """Hex or decimal, spaces after the comma, trailing comments, ignored lines: same entries as canonical."""
    lines = []
    for entry in entries:
        index = data.draw(st.sampled_from([str(entry.index), f"0x{entry.index:x}", f"0X{entry.index:04X}"]))
        sub = data.draw(st.sampled_from([str(entry.sub), f"0x{entry.sub:X}", f" {entry.sub}"]))
        value = (
            entry.value
            if isinstance(entry.value, str)
            else data.draw(
                st.sampled_from([str(entry.value), f"{'-' if entry.value < 0 else ''}0x{abs(entry.value):x}"])
            )
        )
        comment = data.draw(st.sampled_from(["", " ; note", ";"]))
        noise = data.draw(st.sampled_from(["", "; comment\n", "\n", "Title line\n", "\t0x1,1=1\n"]))
        lines.append(f"{noise}{index},{sub}={value}{comment}\n")
    assert parse_object_file("".join(lines)) == entries


@settings(deadline=None)
@given(st.text(alphabet=st.sampled_from("0123456789xX,=;- abA\n\r"), max_size=80))
def test_arbitrary_text_is_parsed_or_rejected_cleanly(text: str) -> None:
    try:
        entries = parse_object_file(text, "F.TXT")
    except ObjectFileError as error:
        assert error.file == "F.TXT" and 1 <= error.line <= text.count("\n") + 1 and error.reason
    else:
        assert all(0 <= entry.index <= 0xFFFF and 0 <= entry.sub <= 0xFF for entry in entries)
