"""A small, strict subset of TOML for project and motor files, with a stable writer.

Why not a general TOML library: project files live in git, so the writer must produce byte-identical output for the
same content and change exactly one line when one value changes; and every error must name the file and the line,
which ``tomllib`` cannot do for semantic errors found after parsing. The subset is valid TOML, so other tools can read
the files.

Subset:
- ``# comment`` lines and blank lines;
- table headers ``[a]`` / ``[a.b]`` whose keys are bare (``A-Za-z0-9_-``) or basic quoted strings;
- ``key = value`` with value one of: basic string ``"..."`` (escapes ``\\" \\\\ \\b \\t \\n \\f \\r \\uXXXX
  \\UXXXXXXXX``), decimal integer, float (digits with ``.`` and/or exponent), ``true`` / ``false``;
- an optional ``# comment`` after a header or a value.

A document is an ordered mapping ``table path -> Table``; keys keep their order. Keys directly at the top level
(outside any table) are not part of the subset.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import NoReturn

from servostudio.services.projects.errors import FileFormatError

Value = str | int | float | bool
TablePath = tuple[str, ...]

_BARE_KEY = re.compile(r"[A-Za-z0-9_-]+")
_INTEGER = re.compile(r"[+-]?(0|[1-9][0-9]*)")
_FLOAT = re.compile(r"[+-]?(0|[1-9][0-9]*)(\.[0-9]+([eE][+-]?[0-9]+)?|[eE][+-]?[0-9]+)")
_CONTROL = re.compile(r"[\x00-\x08\x0a-\x1f\x7f]")
_ESCAPES = {'"': '"', "\\": "\\", "b": "\b", "t": "\t", "n": "\n", "f": "\f", "r": "\r"}
_WRITE_ESCAPES = {'"': '\\"', "\\": "\\\\", "\b": "\\b", "\t": "\\t", "\n": "\\n", "\f": "\\f", "\r": "\\r"}


@dataclass
class Table:
    """One ``[header]`` with its values in file order, and the line of each (1-based) for error messages."""

    line: int = 0
    values: dict[str, Value] = field(default_factory=dict)
    lines: dict[str, int] = field(default_factory=dict)


Document = dict[TablePath, Table]


def parse(text: str, source: Path | str = "<text>") -> Document:
    """Parse ``text``; raise :class:`FileFormatError` naming ``source`` and the line on the first error."""
    document: Document = {}
    current: Table | None = None
    current_path: TablePath = ()
    for number, raw in enumerate(text.split("\n"), start=1):
        line = raw.removesuffix("\r").strip(" \t")
        control = _CONTROL.search(line)
        if control:
            raise FileFormatError(
                source,
                number,
                f"control character U+{ord(control.group()):04X} is not allowed "
                "(write it as an escape inside a quoted string)",
            )
        if not line or line.startswith("#"):
            continue
        cursor = _Cursor(line, source, number)
        if line.startswith("["):
            path = _parse_header(cursor)
            if path in document:
                cursor.fail(f"table [{format_path(path)}] is defined twice (first at line {document[path].line})")
            _check_no_key_clash(document, path, cursor)
            current_path = path
            current = document[path] = Table(line=number)
            continue
        if current is None:
            cursor.fail("a value outside any [table]; start the file with a table header")
        key = _parse_key(cursor)
        cursor.skip_spaces()
        cursor.expect("=")
        cursor.skip_spaces()
        value = _parse_value(cursor)
        cursor.expect_end()
        if key in current.values:
            cursor.fail(f"key {key!r} is set twice in this table (first at line {current.lines[key]})")
        if any(path[: len(current_path) + 1] == (*current_path, key) for path in document):
            cursor.fail(f"key {key!r} is also the name of a table")
        current.values[key] = value
        current.lines[key] = number
    return document


def dump(document: Document, header_comment: str = "") -> str:
    """Write ``document`` in its own order; the same document always gives the same text."""
    out: list[str] = [f"# {line}".rstrip() for line in header_comment.splitlines()]
    for path, table in document.items():
        if out:
            out.append("")
        out.append(f"[{format_path(path)}]")
        out.extend(f"{format_key(key)} = {format_value(value)}" for key, value in table.values.items())
    return "\n".join(out) + "\n"


def format_path(path: TablePath) -> str:
    return ".".join(format_key(part) for part in path)


def format_key(key: str) -> str:
    return key if _BARE_KEY.fullmatch(key) else format_value(key)


def format_value(value: Value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if not math.isfinite(value):
            raise ValueError(f"cannot write {value!r}: only finite numbers are allowed")
        text = repr(value)
        return text if ("." in text or "e" in text) else text + ".0"
    if isinstance(value, str):
        return '"' + "".join(_escape(char) for char in value) + '"'
    raise TypeError(f"cannot write a value of type {type(value).__name__}")


def _escape(char: str) -> str:
    if char in _WRITE_ESCAPES:
        return _WRITE_ESCAPES[char]
    if ord(char) < 0x20 or ord(char) == 0x7F:
        return f"\\u{ord(char):04X}"
    return char


class _Cursor:
    """Reads one line left to right; every failure names the file, the line and the column."""

    def __init__(self, line: str, source: Path | str, number: int) -> None:
        self.text = line
        self.pos = 0
        self.source = source
        self.number = number

    def fail(self, reason: str) -> NoReturn:
        raise FileFormatError(self.source, self.number, reason)

    def peek(self) -> str:
        return self.text[self.pos] if self.pos < len(self.text) else ""

    def skip_spaces(self) -> None:
        while self.peek() in (" ", "\t"):
            self.pos += 1

    def expect(self, char: str) -> None:
        if self.peek() != char:
            found = repr(self.peek()) if self.peek() else "end of line"
            self.fail(f"expected {char!r} at column {self.pos + 1}, found {found}")
        self.pos += 1

    def expect_end(self) -> None:
        self.skip_spaces()
        if self.peek() and self.peek() != "#":
            self.fail(f"unexpected text {self.text[self.pos :]!r} at column {self.pos + 1}")


def _check_no_key_clash(document: Document, path: TablePath, cursor: _Cursor) -> None:
    """TOML forbids a table whose name is already a plain key of its parent table."""
    for depth in range(1, len(path)):
        parent = document.get(path[:depth])
        if parent is not None and path[depth] in parent.values:
            cursor.fail(
                f"table [{format_path(path)}] clashes with key {path[depth]!r} of [{format_path(path[:depth])}]"
            )


def _parse_header(cursor: _Cursor) -> TablePath:
    cursor.expect("[")
    parts = []
    while True:
        cursor.skip_spaces()
        parts.append(_parse_key(cursor))
        cursor.skip_spaces()
        if cursor.peek() != ".":
            break
        cursor.pos += 1
    cursor.expect("]")
    cursor.expect_end()
    return tuple(parts)


def _parse_key(cursor: _Cursor) -> str:
    if cursor.peek() == '"':
        return _parse_string(cursor)
    match = _BARE_KEY.match(cursor.text, cursor.pos)
    if not match:
        cursor.fail(f"expected a key at column {cursor.pos + 1} (letters, digits, '_', '-', or a quoted string)")
    cursor.pos = match.end()
    return match.group()


def _parse_value(cursor: _Cursor) -> Value:
    if cursor.peek() == '"':
        return _parse_string(cursor)
    token = re.match(r"[^\s#]+", cursor.text[cursor.pos :])
    if not token:
        cursor.fail("a value is missing after '='")
    word = token.group()
    cursor.pos += len(word)
    if word in ("true", "false"):
        return word == "true"
    if _INTEGER.fullmatch(word):
        return int(word)
    if _FLOAT.fullmatch(word):
        return float(word)
    cursor.fail(f"value {word!r} is not a quoted string, a decimal integer, a number or true/false")
    raise AssertionError("unreachable")


def _parse_string(cursor: _Cursor) -> str:
    cursor.expect('"')
    chars: list[str] = []
    while True:
        char = cursor.peek()
        if not char:
            cursor.fail("string is not closed with '\"' on this line")
        cursor.pos += 1
        if char == '"':
            return "".join(chars)
        if char == "\\":
            chars.append(_parse_escape(cursor))
        else:
            chars.append(char)


def _parse_escape(cursor: _Cursor) -> str:
    code = cursor.peek()
    cursor.pos += 1
    if code in _ESCAPES:
        return _ESCAPES[code]
    if code in ("u", "U"):
        width = 4 if code == "u" else 8
        digits = cursor.text[cursor.pos : cursor.pos + width]
        if len(digits) != width or not re.fullmatch(r"[0-9A-Fa-f]+", digits):
            cursor.fail(f"\\{code} needs {width} hex digits")
        cursor.pos += width
        point = int(digits, 16)
        if point > 0x10FFFF or 0xD800 <= point <= 0xDFFF:
            cursor.fail(f"\\{code}{digits} is not a Unicode scalar value")
        return chr(point)
    cursor.fail(f"unknown escape sequence \\{code}")
    raise AssertionError("unreachable")
