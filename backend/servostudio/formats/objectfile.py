"""The XtrapulsPac object file: DRIVEPAR.TXT and USER_PAR.TXT (manual §3.2.6.1).

One assignment per line, ``index, sub=value``; numbers decimal or ``0x`` hex; ``;`` starts a comment; the drive
ignores every line that does not begin with a digit, and so does this reader (an indented line is ignored too,
exactly as on the drive). A line that does begin with a digit must be a valid assignment, and an object may be
assigned only once: both are errors here, so a file the tool accepts means the same thing to the drive.

The parser stands alone; a caller that knows the object dictionary passes ``validate`` to check each entry.
"""

from __future__ import annotations

import os
import re
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path

from servostudio.errors import InvalidInput
from servostudio.formats.numbers import parse_integer
from servostudio.formats.textfile import FILE_ENCODING, split_lines, write_text_atomic

MAX_INDEX = 0xFFFF
MAX_SUB = 0xFF

#: A value that starts like a number must be a number; anything else is kept as raw text.
_LOOKS_NUMERIC = re.compile(r"[+-]?[0-9]")

#: A callable that checks one entry (e.g. against an object dictionary) and returns a reason, or None if fine.
EntryValidator = Callable[["ObjectEntry"], "str | None"]


@dataclass(frozen=True)
class ObjectEntry:
    """One assignment ``index,sub=value``; ``line`` is where it was read (0 when built in code).

    The line number does not take part in equality, so a file read back after writing compares equal.
    """

    index: int
    sub: int
    value: int | str
    line: int = field(default=0, compare=False)


class ObjectFileError(InvalidInput):
    """A malformed or duplicate assignment, located as ``FILE:LINE: reason``."""

    def __init__(self, file: str, line: int, reason: str) -> None:
        super().__init__(f"{file}:{line}: {reason}")
        self.file = file
        self.line = line
        self.reason = reason


def parse_object_file(
    text: str,
    file: str = "<string>",
    validate: EntryValidator | None = None,
    spelled: Callable[[int, int], str] | None = None,
) -> list[ObjectEntry]:
    """Parse object-file text into its entries, in file order; raise ObjectFileError on the first bad line.
    ``spelled`` names an address in messages (default ``0xIIII,sub``)."""
    entries: list[ObjectEntry] = []
    first_line: dict[tuple[int, int], int] = {}
    for number, raw in enumerate(split_lines(text), start=1):
        if not raw or raw[0] not in "0123456789":
            continue
        try:
            entry = _parse_assignment(raw.split(";", 1)[0], number)
        except ValueError as error:
            raise ObjectFileError(file, number, str(error)) from None
        key = (entry.index, entry.sub)
        if key in first_line:
            raise ObjectFileError(
                file,
                number,
                f"duplicate assignment of {(spelled or _key_text)(*key)} (first at line {first_line[key]})",
            )
        first_line[key] = number
        reason = validate(entry) if validate is not None else None
        if reason is not None:
            raise ObjectFileError(file, number, reason)
        entries.append(entry)
    return entries


def read_object_file(path: str | os.PathLike[str], validate: EntryValidator | None = None) -> list[ObjectEntry]:
    """Read and parse an object file from disk (8-bit text)."""
    return parse_object_file(Path(path).read_text(encoding=FILE_ENCODING), str(path), validate)


def format_object_file(entries: Iterable[ObjectEntry], header: str | None = None) -> str:
    """Render entries in the one canonical form: sorted by (index, sub), ``0xIIII,sub=value``, decimal values.

    A stable order and a single spelling make two saves of the same parameters byte-identical, so a diff
    shows only real changes. Raises ValueError for entries that could not be read back.
    """
    lines = [_comment(text) for text in split_lines(header)] if header else []
    previous: tuple[int, int] | None = None
    for entry in sorted(entries, key=lambda item: (item.index, item.sub)):
        key = (entry.index, entry.sub)
        if key == previous:
            raise ValueError(f"duplicate entry {_key_text(*key)}")
        previous = key
        lines.append(_format_entry(entry))
    return "".join(line + "\n" for line in lines)


def write_object_file(path: str | os.PathLike[str], entries: Iterable[ObjectEntry], header: str | None = None) -> None:
    """Write entries in canonical form, atomically (the old file stays intact if anything fails)."""
    write_text_atomic(path, format_object_file(entries, header))


def _parse_assignment(text: str, line: int) -> ObjectEntry:
    target, equals, value_text = text.partition("=")
    if not equals:
        raise ValueError("expected 'index,sub=value' (no '=')")
    parts = target.split(",")
    if len(parts) != 2:
        raise ValueError("expected 'index,sub' before '=' (exactly one comma)")
    index = _parse_number(parts[0].strip(), "index", MAX_INDEX)
    sub = _parse_number(parts[1].strip(), "sub-index", MAX_SUB)
    return ObjectEntry(index, sub, _parse_value(value_text.strip()), line)


def _parse_number(text: str, what: str, maximum: int) -> int:
    value = parse_integer(text)
    if value is None:
        raise ValueError(f"{what} {text!r} is not a decimal or 0x hex number")
    if not 0 <= value <= maximum:
        raise ValueError(f"{what} {text} out of range 0..0x{maximum:X}")
    return value


def _parse_value(text: str) -> int | str:
    if not text:
        raise ValueError("missing value after '='")
    if _LOOKS_NUMERIC.match(text):
        value = parse_integer(text)
        if value is None:
            raise ValueError(f"value {text!r} is not a decimal or 0x hex number")
        return value
    return text


def _format_entry(entry: ObjectEntry) -> str:
    if not 0 <= entry.index <= MAX_INDEX or not 0 <= entry.sub <= MAX_SUB:
        raise ValueError(f"index/sub out of range: {entry.index:#x},{entry.sub}")
    if isinstance(entry.value, str):
        _check_text_value(entry)
        value = entry.value
    else:
        value = str(int(entry.value))
    return f"0x{entry.index:04X},{entry.sub}={value}"


def _check_text_value(entry: ObjectEntry) -> None:
    """A text value must survive the reader unchanged: not numeric-looking, no comment or line break."""
    text = entry.value
    assert isinstance(text, str)
    problem = None
    if not text or text != text.strip():
        problem = "is empty or has leading/trailing spaces"
    elif _LOOKS_NUMERIC.match(text):
        problem = "starts like a number"
    elif any(char in text for char in ";\r\n"):
        problem = "contains ';' or a line break"
    else:
        try:
            text.encode(FILE_ENCODING)
        except UnicodeEncodeError:
            problem = f"is not {FILE_ENCODING} text"
    if problem:
        raise ValueError(f"text value of {_key_text(entry.index, entry.sub)} {problem}: {text!r}")


def _comment(text: str) -> str:
    return f"; {text}" if text.strip() else ";"


def _key_text(index: int, sub: int) -> str:
    return f"0x{index:04X},{sub}"
