"""SEQUENCE.TXT as the editor, the REST API and the CLI see it: checked by the file reader (the one validation),
shown as JSON in the file's own spellings, and its chaining graph."""

from __future__ import annotations

from servostudio.formats.sequence import (
    BitPattern,
    Sequence,
    SequenceFileError,
    SequenceIssue,
    SequenceTable,
    SequenceType,
    keywords_for,
    parse_sequence_text,
)
from servostudio.formats.sequence_model import default_value, value_problem
from servostudio.formats.sequence_spec import Keyword
from servostudio.services.sequences.graph import ALL_TYPES, chaining_graph
from servostudio.services.sequences.memory import FILE, DriveLimits

#: what a file is checked against when no drive is asked: 128 sequences of every type
OFFLINE = DriveLimits(128, ALL_TYPES)


def parse(text: str, file: str = FILE, found: DriveLimits = OFFLINE) -> SequenceTable:
    """The table, or ``SequenceFileError`` with every issue (file, line, keyword, reason with the allowed range)."""
    return parse_sequence_text(text, file, max_sequences=found.count, types=found.types)


def issue_dict(file: str, issue: SequenceIssue) -> dict[str, object]:
    return {"file": file, "line": issue.line, "keyword": issue.keyword, "reason": issue.reason}


def check(text: str, file: str = FILE, found: DriveLimits = OFFLINE) -> dict[str, object]:
    """The verdict on a file without raising: its issues, or its sequences and graph (what the editor shows)."""
    try:
        table = parse(text, file, found)
    except SequenceFileError as error:
        return {"file": file, "ok": False, "issues": [issue_dict(file, issue) for issue in error.issues]}
    return {"file": file, "ok": True, "issues": [], **show(table), "graph": graph(table, found)}


def show(table: SequenceTable) -> dict[str, object]:
    """Every sequence with every parameter in the file's spelling (constants by name, patterns as 8 characters);
    None for a default the file cannot spell (no trigger, ``AccelTime`` 0, ``Method`` 0)."""
    return {"sequences": [sequence_dict(number, sequence) for number, sequence in table.sequences.items()]}


def sequence_dict(number: int, sequence: Sequence) -> dict[str, object]:
    values = {keyword.name: spelled(keyword, sequence.values[keyword.name]) for keyword in keywords_for(sequence.type)}
    return {"sequence": number, "type": sequence.type.name, "values": values}


def spelled(keyword: Keyword, value: int | BitPattern) -> int | str | None:
    if isinstance(value, BitPattern):
        return str(value).strip('"')
    if value_problem(keyword, value) is not None:
        return None
    return keyword.constant_name(value) if keyword.constants is not None else value


def graph(table: SequenceTable, found: DriveLimits = OFFLINE) -> dict[str, object]:
    return chaining_graph(table, found.types_mask, found.count).as_dict()


def keyword_catalog() -> dict[str, object]:
    """The editor's fields per type: keyword, 0x3611 sub, unit, what a file may write, default, constants."""
    return {
        "types": [kind.name for kind in SequenceType],
        "keywords": {kind.name: [_keyword_dict(keyword) for keyword in keywords_for(kind)] for kind in SequenceType},
    }


def _keyword_dict(keyword: Keyword) -> dict[str, object]:
    default = default_value(keyword)
    return {
        "name": keyword.name,
        "aliases": list(keyword.aliases),
        "subs": list(keyword.subs),
        "unit": keyword.sub.unit,
        "pattern": keyword.is_pattern,
        "constants": list(keyword.constants) if keyword.constants is not None else None,
        "allowed": [list(interval) for interval in keyword.value_range.intervals] if not keyword.is_pattern else None,
        "default": spelled(keyword, default),
    }
