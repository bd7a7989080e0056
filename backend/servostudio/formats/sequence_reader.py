"""Reading SEQUENCE.TXT (manual L11128–11170) into a ``SequenceTable``, reporting every error at once.

The drive rejects a whole file that has one bad line (error 44 "Sequence file error"), so the reader collects
all issues, each with its line, keyword and reason, and returns a table only when there are none: a caller
never sees a partial result it could write to a drive.

Lines are read in order. ``Default`` starts a block of default values that holds until the next ``SeqNb``;
the defaults in effect when a sequence starts apply to that sequence's undeclared parameters. ``SeqNb``
starts a sequence, which ends at the next ``SeqNb`` or ``Default`` line. Keywords are resolved against the
sequence's type only once the whole sequence is read, since parameter order does not matter (rule 6).
"""

from __future__ import annotations

import os
from collections.abc import Collection
from dataclasses import dataclass, field
from pathlib import Path

from servostudio.errors import InvalidInput
from servostudio.formats.numbers import parse_integer
from servostudio.formats.sequence_model import BitPattern, Sequence, SequenceTable, Value, value_problem
from servostudio.formats.sequence_spec import (
    DEFAULT_BLOCK,
    MAX_SEQUENCES,
    SEQ_NB,
    SEQ_TYPE,
    Keyword,
    SequenceType,
    find_any_type,
    find_keyword,
    keywords_for,
    normalize,
)
from servostudio.formats.textfile import FILE_ENCODING, split_lines


@dataclass(frozen=True)
class SequenceIssue:
    """One problem in a sequence file: where (line), which keyword (None for a line without one), why."""

    line: int
    keyword: str | None
    reason: str

    def __str__(self) -> str:
        where = f"{self.keyword}: " if self.keyword else ""
        return f"line {self.line}: {where}{self.reason}"


class SequenceFileError(InvalidInput):
    """Every problem found in a sequence file; ``issues`` is ordered by line."""

    def __init__(self, file: str, issues: list[SequenceIssue]) -> None:
        self.file = file
        self.issues = tuple(sorted(issues, key=lambda issue: issue.line))
        details = "\n".join(f"{file}:{issue.line}: {_located(issue)}" for issue in self.issues)
        super().__init__(f"{file}: {len(self.issues)} error(s) in sequence file\n{details}")


def _located(issue: SequenceIssue) -> str:
    return f"{issue.keyword}: {issue.reason}" if issue.keyword else issue.reason


def parse_sequence_text(
    text: str,
    file: str = "<string>",
    *,
    max_sequences: int = MAX_SEQUENCES,
    types: Collection[SequenceType] | None = None,
) -> SequenceTable:
    """Parse SEQUENCE.TXT text; ``max_sequences`` is the drive's 0x3612 (sequence numbers 0..max−1), ``types``
    the sequence types it supports (0x360F; None: every type) — a sequence of another type is an error at its
    ``SeqType`` line, as the drive raises error 44 for it."""
    if max_sequences < 1:
        raise ValueError(f"max_sequences must be at least 1, got {max_sequences}")
    reader = _Reader(min(max_sequences, MAX_SEQUENCES), tuple(SequenceType) if types is None else tuple(types))
    for number, raw in enumerate(split_lines(text), start=1):
        reader.feed(number, raw)
    table = reader.finish()
    if reader.issues:
        raise SequenceFileError(file, list(reader.issues))
    return table


def read_sequence_file(
    path: str | os.PathLike[str], *, max_sequences: int = MAX_SEQUENCES, types: Collection[SequenceType] | None = None
) -> SequenceTable:
    """Read and parse a SEQUENCE.TXT from disk (8-bit text)."""
    text = Path(path).read_text(encoding=FILE_ENCODING)
    return parse_sequence_text(text, str(path), max_sequences=max_sequences, types=types)


@dataclass(frozen=True)
class _Assignment:
    line: int
    key: str
    text: str


@dataclass
class _Block:
    """The lines of one sequence, kept until the sequence is complete."""

    line: int
    number: int | None
    defaults: tuple[_Assignment, ...]
    assignments: list[_Assignment] = field(default_factory=list)


class _Reader:
    def __init__(self, max_sequences: int, types: tuple[SequenceType, ...]) -> None:
        self.max_sequences = max_sequences
        self.types = types
        self.issues: dict[SequenceIssue, None] = {}  # an ordered set: a default may fail the same way twice
        self.defaults: list[_Assignment] = []
        self.blocks: list[_Block] = []
        self.declared_at: dict[int, int] = {}
        self.in_default = False

    def report(self, line: int, keyword: str | None, reason: str) -> None:
        self.issues[SequenceIssue(line, keyword, reason)] = None

    def feed(self, line: int, raw: str) -> None:
        content = raw.split(";", 1)[0].strip()
        if not content:
            return
        if normalize(content) == normalize(DEFAULT_BLOCK):
            self.in_default = True
            return
        key, equals, text = content.partition("=")
        key, text = key.strip(), text.strip()
        if not equals or not key:
            self.report(line, None, f"expected 'Key_word = value' (one keyword per line), got {content!r}")
        elif normalize(key) == normalize(SEQ_NB):
            self.start_sequence(_Assignment(line, key, text))
        elif self.in_default:
            self.add_default(_Assignment(line, key, text))
        elif self.blocks:
            self.blocks[-1].assignments.append(_Assignment(line, key, text))
        else:
            self.report(line, key, "a sequence begins with SeqNb: no SeqNb (or Default) before this line")

    def start_sequence(self, assignment: _Assignment) -> None:
        self.in_default = False
        number = parse_integer(assignment.text)
        if number is None:
            self.report(
                assignment.line, assignment.key, f"{assignment.text!r} is not a sequence number (decimal or 0x hex)"
            )
        elif not 0 <= number < self.max_sequences:
            self.report(
                assignment.line,
                assignment.key,
                f"sequence number {number} is out of range: allowed 0..{self.max_sequences - 1}",
            )
            number = None
        elif number in self.declared_at:
            self.report(
                assignment.line,
                assignment.key,
                f"sequence {number} is already declared at line {self.declared_at[number]}",
            )
            number = None
        else:
            self.declared_at[number] = assignment.line
        self.blocks.append(_Block(assignment.line, number, tuple(self.defaults)))

    def add_default(self, assignment: _Assignment) -> None:
        keyword = find_any_type(assignment.key)
        if keyword is None:
            self.report(assignment.line, assignment.key, "unknown keyword")
        elif self.parse(assignment, keyword) is not None:
            self.defaults.append(assignment)

    def parse(self, assignment: _Assignment, keyword: Keyword, context: str | None = None) -> Value | None:
        """The value of one assignment, or None after reporting why it is invalid.

        Without ``context`` only the syntax is checked (a ``Default`` line: its range depends on the type of
        the sequence it ends up in); with it, e.g. ``"[SPEED sequence 3]"``, the range too.
        """
        try:
            value = _parse_value(keyword, assignment.text)
        except ValueError as error:
            self.report(assignment.line, assignment.key, str(error))
            return None
        problem = value_problem(keyword, value) if context is not None else None
        if problem is not None:
            self.report(assignment.line, assignment.key, f"{problem} {context}")
            return None
        return value

    def finish(self) -> SequenceTable:
        sequences: dict[int, Sequence] = {}
        for block in self.blocks:
            sequence = self.resolve(block)
            if sequence is not None and block.number is not None:
                sequences[block.number] = sequence
        return SequenceTable(sequences)

    def resolve(self, block: _Block) -> Sequence | None:
        """Check a sequence's lines against its type; the Sequence, or None after reporting its issues."""
        issues_before = len(self.issues)
        kind = self.sequence_type(block)
        if kind is None:
            for assignment in block.assignments:
                if normalize(assignment.key) not in SEQ_TYPE.spellings and find_any_type(assignment.key) is None:
                    self.report(assignment.line, assignment.key, "unknown keyword")
            return None
        label = f"{kind.name} sequence {_number_text(block)}"
        values: dict[str, Value] = {}
        declared_at: dict[str, int] = {}
        for assignment in block.assignments:
            if normalize(assignment.key) in SEQ_TYPE.spellings:
                continue
            keyword = find_keyword(kind, assignment.key)
            if keyword is None:
                self.report_misplaced(assignment, kind)
            elif keyword.name in declared_at:
                self.report(
                    assignment.line,
                    assignment.key,
                    f"{keyword.name} is declared twice in {label} (first at line {declared_at[keyword.name]})",
                )
            else:
                declared_at[keyword.name] = assignment.line
                value = self.parse(assignment, keyword, context=f"[{label}]")
                if value is not None:
                    values[keyword.name] = value
        for keyword in keywords_for(kind):
            default = _last_default_for(block.defaults, kind, keyword)
            if keyword.name not in declared_at and default is not None:
                value = self.parse(default, keyword, context=f"[Default, applied to {label}]")
                if value is not None:
                    values[keyword.name] = value
        if len(self.issues) > issues_before or block.number is None:
            return None
        return Sequence(kind, values)

    def sequence_type(self, block: _Block) -> SequenceType | None:
        declared = [a for a in block.assignments if normalize(a.key) in SEQ_TYPE.spellings]
        for repeated in declared[1:]:
            self.report(repeated.line, repeated.key, f"SeqType is declared twice (first at line {declared[0].line})")
        defaults = [a for a in block.defaults if normalize(a.key) in SEQ_TYPE.spellings]
        source = declared[0] if declared else defaults[-1] if defaults else None
        if source is None:
            self.report(
                block.line,
                SEQ_NB,
                f"sequence {_number_text(block)} has no SeqType (allowed: {', '.join(SequenceType.__members__)})",
            )
            return None
        value = self.parse(source, SEQ_TYPE)
        if not isinstance(value, int):
            return None
        if SequenceType(value) not in self.types:
            allowed = ", ".join(kind.name for kind in self.types) or "none"
            self.report(
                source.line,
                source.key,
                f"{SequenceType(value).name} sequences are not supported by the drive (0x360F): allowed {allowed}",
            )
            return None
        return SequenceType(value)

    def report_misplaced(self, assignment: _Assignment, kind: SequenceType) -> None:
        if find_any_type(assignment.key) is None:
            self.report(assignment.line, assignment.key, "unknown keyword")
            return
        allowed = ", ".join(keyword.name for keyword in keywords_for(kind))
        self.report(
            assignment.line, assignment.key, f"not a keyword of {kind.name} sequences (allowed: SeqType, {allowed})"
        )


def _number_text(block: _Block) -> str:
    return "?" if block.number is None else str(block.number)


def _last_default_for(defaults: tuple[_Assignment, ...], kind: SequenceType, keyword: Keyword) -> _Assignment | None:
    """The latest Default assignment that sets ``keyword`` for this type (any alias spelling)."""
    matching = [a for a in defaults if find_keyword(kind, a.key) is keyword]
    return matching[-1] if matching else None


def _parse_value(keyword: Keyword, text: str) -> Value:
    """Syntax of a value (number, constant or pattern); ranges are checked once the type is known."""
    if keyword.is_pattern:
        return BitPattern.parse(text)
    if keyword.constants is not None:
        value = keyword.constants.get(text.upper())
        if value is None:
            raise ValueError(f"{text!r} is not a {keyword.name} constant; allowed: {', '.join(keyword.constants)}")
        return value
    number = parse_integer(text)
    if number is None:
        raise ValueError(f"{text!r} is not a number (decimal or 0x hex)")
    return number
