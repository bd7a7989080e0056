"""Writing a ``SequenceTable`` as SEQUENCE.TXT in one canonical form.

Canonical means: sequences by ascending number, separated by a blank line; ``SeqNb`` then ``SeqType`` then
every parameter of the type in a fixed order (type-specific ones as the manual lists them, then Tempo,
Trigger, Output, StartCond, EndCond, SeqNext, SeqCount, SeqLink); one spelling per keyword; decimal numbers,
upper-case constants, quoted patterns; no ``Default`` block. Every parameter is written explicitly, so the
file means the same whatever defaults the drive assumes, except a parameter at a drive default that the
file syntax cannot spell (``Trigger`` none, ``AccelTime``/``Method`` 0), which is left out.
"""

from __future__ import annotations

import os

from servostudio.formats.sequence_model import BitPattern, SequenceTable, Value, value_problem
from servostudio.formats.sequence_spec import SEQ_NB, SEQ_TYPE, Keyword, keywords_for
from servostudio.formats.textfile import split_lines, write_text_atomic


def format_sequence_table(table: SequenceTable, header: str | None = None) -> str:
    """Render a table as SEQUENCE.TXT text; ``header`` becomes leading ``;`` comment lines."""
    lines = [f"; {text}" if text.strip() else ";" for text in split_lines(header)] if header else []
    for number, sequence in table.sequences.items():
        if lines:
            lines.append("")
        lines.append(f"{SEQ_NB}={number}")
        lines.append(f"{SEQ_TYPE.name}={sequence.type.name}")
        for keyword in keywords_for(sequence.type):
            text = _value_text(keyword, sequence.values[keyword.name])
            if text is not None:
                lines.append(f"{keyword.name}={text}")
    return "".join(line + "\n" for line in lines)


def write_sequence_file(path: str | os.PathLike[str], table: SequenceTable, header: str | None = None) -> None:
    """Write a table as SEQUENCE.TXT, atomically (the old file stays intact if anything fails)."""
    write_text_atomic(path, format_sequence_table(table, header))


def _value_text(keyword: Keyword, value: Value) -> str | None:
    """The file spelling of a value, or None for a default the syntax cannot spell (left out)."""
    if isinstance(value, BitPattern):
        return str(value)
    if value_problem(keyword, value) is not None:
        return None
    if keyword.constants is not None:
        return keyword.constant_name(value)
    return str(value)
