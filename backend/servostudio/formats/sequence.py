"""SEQUENCE.TXT, the XtrapulsPac sequence file: model, reader and writer in one import.

Import from here: ``from servostudio.formats.sequence import parse_sequence_text, format_sequence_table``.
"""

from servostudio.formats.sequence_model import (
    BitPattern,
    LoadMode,
    ObjectWrite,
    Sequence,
    SequenceTable,
    Value,
)
from servostudio.formats.sequence_reader import (
    SequenceFileError,
    SequenceIssue,
    parse_sequence_text,
    read_sequence_file,
)
from servostudio.formats.sequence_spec import MAX_SEQUENCES, SequenceType, keywords_for
from servostudio.formats.sequence_writer import format_sequence_table, write_sequence_file

__all__ = [
    "MAX_SEQUENCES",
    "BitPattern",
    "LoadMode",
    "ObjectWrite",
    "Sequence",
    "SequenceFileError",
    "SequenceIssue",
    "SequenceTable",
    "SequenceType",
    "Value",
    "format_sequence_table",
    "keywords_for",
    "parse_sequence_text",
    "read_sequence_file",
    "write_sequence_file",
]
