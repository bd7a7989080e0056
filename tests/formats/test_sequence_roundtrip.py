"""Property tests: any table survives file writing and object values; any spelling the rules allow reads the same."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

from hypothesis import given, settings
from hypothesis import strategies as st

from servostudio.formats.sequence import (
    BitPattern,
    Sequence,
    SequenceFileError,
    SequenceTable,
    SequenceType,
    format_sequence_table,
    keywords_for,
    parse_sequence_text,
    read_sequence_file,
    write_sequence_file,
)
from servostudio.formats.sequence_model import default_value, value_problem
from servostudio.formats.sequence_spec import Keyword

PATTERNS = st.tuples(st.integers(0, 255), st.integers(0, 255)).map(
    lambda pair: BitPattern(zeros=pair[0] & ~pair[1], ones=pair[1])
)


def values_of(keyword: Keyword) -> st.SearchStrategy:
    """Every value a file can write for the keyword, plus its default (which may lie outside that range)."""
    if keyword.is_pattern:
        return PATTERNS
    in_range = st.one_of(*(st.integers(low, high) for low, high in keyword.value_range.intervals))
    return st.one_of(in_range, st.just(default_value(keyword)))


def sequences_of(kind: SequenceType) -> st.SearchStrategy[Sequence]:
    optional = {keyword.name: values_of(keyword) for keyword in keywords_for(kind)}
    return st.fixed_dictionaries({}, optional=optional).map(lambda values: Sequence(kind, values))


SEQUENCES = st.sampled_from(list(SequenceType)).flatmap(sequences_of)
TABLES = st.dictionaries(st.integers(0, 127), SEQUENCES, max_size=6).map(SequenceTable)


@settings(deadline=None)
@given(TABLES, st.one_of(st.none(), st.text(alphabet="abc ;=\n", max_size=20)))
def test_write_then_read_gives_the_same_table(table: SequenceTable, header: str | None) -> None:
    text = format_sequence_table(table, header)
    read_back = parse_sequence_text(text)
    assert read_back == table
    assert format_sequence_table(read_back, header) == text


@settings(max_examples=25, deadline=None)
@given(TABLES)
def test_write_then_read_through_a_file(table: SequenceTable) -> None:
    with tempfile.TemporaryDirectory() as directory:
        path = Path(directory) / "SEQUENCE.TXT"
        write_sequence_file(path, table, header="saved by Servo Studio")
        assert read_sequence_file(path) == table
        assert os.listdir(directory) == ["SEQUENCE.TXT"]


@settings(deadline=None)
@given(TABLES)
def test_object_values_round_trip(table: SequenceTable) -> None:
    records = {number: sequence.to_object_values() for number, sequence in table.sequences.items()}
    assert SequenceTable.from_object_values(records) == table
    writes = table.to_object_writes()
    assert len(writes) == 27 * len(table)


def spelled(keyword: Keyword, value: object, data: st.DataObject) -> str:
    """One of the spellings the rules allow for ``keyword = value``: alias, case, spaces, hex, comment."""
    name = data.draw(st.sampled_from([keyword.name, *keyword.aliases]))
    name = data.draw(st.sampled_from([name, name.lower(), name.upper()]))
    if isinstance(value, BitPattern):
        text = str(value)
    elif keyword.constants is not None:
        constant = keyword.constant_name(value)
        assert constant is not None
        text = data.draw(st.sampled_from([constant, constant.lower(), constant.capitalize()]))
    else:
        assert isinstance(value, int)
        sign = "-" if value < 0 else ""
        text = data.draw(st.sampled_from([str(value), f"{sign}0x{abs(value):x}", f"{sign}0X{abs(value):06X}"]))
    before, after = data.draw(st.sampled_from([("", ""), (" ", " "), ("\t", "  ")]))
    comment = data.draw(st.sampled_from(["", " ; why", ";"]))
    return f"{name}{before}={after}{text}{comment}"


@settings(max_examples=40, deadline=None)
@given(TABLES, st.data())
def test_any_allowed_spelling_reads_as_the_table(table: SequenceTable, data: st.DataObject) -> None:
    """Rules 1, 2, 3, 4, 6, 9 at once: case, aliases, spacing, hex, comments, any order, defaults left out."""
    lines: list[str] = []
    for number, sequence in table.sequences.items():
        lines.append(data.draw(st.sampled_from([f"SeqNb={number}", f"seqnb = 0x{number:X}"])))
        type_name = sequence.type.name
        body = [data.draw(st.sampled_from([f"SeqType={type_name}", f"seqtype = {type_name.lower()}"]))]
        for keyword in keywords_for(sequence.type):
            value = sequence[keyword.name]
            if value_problem(keyword, value) is not None:
                continue  # a drive default the syntax cannot spell
            if value == default_value(keyword) and data.draw(st.booleans()):
                continue  # rule 9: undeclared means default
            body.append(spelled(keyword, value, data))
        lines.extend(data.draw(st.permutations(body)))
        lines.extend(data.draw(st.sampled_from([[], [""], ["; next sequence"]])))
    assert parse_sequence_text("\n".join(lines)) == table


FRAGMENTS = st.sampled_from(
    [
        "SeqNb=",
        "SeqType=",
        "POS",
        "speed",
        "HOME",
        "Torque",
        "GEAR",
        "Default",
        "Accel",
        "AccelTime",
        "Decel",
        "Pos",
        "Method",
        "Output",
        "StartCond",
        '"..01..10"',
        '"1"',
        "=",
        ";",
        "\n",
        " ",
        "1",
        "-1",
        "0x",
        "70000",
        "Trigger",
        "begin",
        "SeqNext",
        "Tempo",
        "RunTime",
        "Factor",
    ]
)


@settings(deadline=None)
@given(st.lists(FRAGMENTS, max_size=40).map("".join))
def test_arbitrary_text_gives_a_table_or_located_issues(text: str) -> None:
    try:
        table = parse_sequence_text(text, "F.TXT")
    except SequenceFileError as error:
        assert error.issues
        line_count = text.count("\n") + 1
        assert all(1 <= issue.line <= line_count and issue.reason for issue in error.issues)
    else:
        assert format_sequence_table(table) == format_sequence_table(parse_sequence_text(format_sequence_table(table)))
