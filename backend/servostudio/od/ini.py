"""Line-tracking reader for the CiA 306 INI syntax used by EDS/DCF files and by our `.props` files.

Unlike `configparser`, every section and every key remembers the line it came from, so that each later check (in
`eds.py`, `props.py`) can report `file:line: [section] reason`.

Syntax accepted (CiA 306 §4.2):
- `[name]` starts a section; section names and keys are case-insensitive (their spelling is kept for messages);
- `key=value`, whitespace around key and value ignored;
- `;` starts a comment at the beginning of a line, or after whitespace anywhere in a line (so `a;b` is a value,
  `a ;b` is the value `a`);
- blank lines are ignored; a duplicated section or key, a key outside a section, or a line that is none of the
  above is an error.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from pathlib import Path

from servostudio.od.model import DictionaryError


@dataclass(frozen=True)
class IniEntry:
    key: str
    value: str
    line: int


@dataclass
class IniSection:
    name: str
    line: int
    _entries: dict[str, IniEntry] = field(default_factory=dict)

    def __contains__(self, key: str) -> bool:
        return key.casefold() in self._entries

    def __iter__(self) -> Iterator[IniEntry]:
        return iter(self._entries.values())

    def __len__(self) -> int:
        return len(self._entries)

    def entry(self, key: str) -> IniEntry | None:
        return self._entries.get(key.casefold())

    def get(self, key: str, default: str | None = None) -> str | None:
        entry = self._entries.get(key.casefold())
        return default if entry is None else entry.value

    def line_of(self, key: str) -> int:
        """Line of `key`, or of the section header when the key is absent (where it should have been)."""
        entry = self._entries.get(key.casefold())
        return self.line if entry is None else entry.line

    def add(self, entry: IniEntry, path: Path) -> None:
        lowered = entry.key.casefold()
        if lowered in self._entries:
            first = self._entries[lowered].line
            raise DictionaryError(path, entry.line, self.name, f"duplicate key {entry.key!r} (first on line {first})")
        self._entries[lowered] = entry


@dataclass
class IniFile:
    path: Path
    _sections: dict[str, IniSection] = field(default_factory=dict)

    def __contains__(self, name: str) -> bool:
        return name.casefold() in self._sections

    def __iter__(self) -> Iterator[IniSection]:
        return iter(self._sections.values())

    def section(self, name: str) -> IniSection | None:
        return self._sections.get(name.casefold())

    def known_section(self, name: str) -> IniSection:
        """A section the reader has already found to exist; a KeyError here is a programming error."""
        section = self.section(name)
        if section is None:
            raise KeyError(f"section [{name}] was expected to exist")
        return section

    def add(self, section: IniSection) -> None:
        lowered = section.name.casefold()
        if lowered in self._sections:
            first = self._sections[lowered].line
            raise DictionaryError(self.path, section.line, section.name, f"duplicate section (first on line {first})")
        self._sections[lowered] = section


def read_ini(path: Path) -> IniFile:
    """Read and parse an INI file (UTF-8, with or without BOM; Windows-1252 accepted as a fallback)."""
    path = Path(path)
    return parse_ini(decode_ini(path.read_bytes()), path)


def decode_ini(raw: bytes) -> str:
    """The text of an INI file's bytes: UTF-8 (with or without BOM), else Windows-1252 (what older tools write)."""
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        return raw.decode("cp1252", errors="replace")


def parse_ini(text: str, path: Path) -> IniFile:
    ini = IniFile(Path(path))
    current: IniSection | None = None
    for number, line in enumerate(text.splitlines(), start=1):
        content = _strip_comment(line).strip()
        if not content:
            continue
        if content.startswith("["):
            current = _parse_header(content, number, ini.path)
            ini.add(current)
            continue
        key, sep, value = content.partition("=")
        key = key.strip()
        if not sep or not key:
            where = current.name if current is not None else "-"
            raise DictionaryError(ini.path, number, where, f"expected 'key=value' or '[section]', got {content!r}")
        if current is None:
            raise DictionaryError(ini.path, number, "-", f"key {key!r} appears before any [section]")
        current.add(IniEntry(key, value.strip(), number), ini.path)
    return ini


def format_ini(sections: Iterable[tuple[str, Iterable[tuple[str, str]]]]) -> str:
    """Write sections as INI text that `parse_ini` reads back to the same names, keys and values."""
    blocks = []
    for name, entries in sections:
        lines = [f"[{name}]"] + [f"{key}={value}" for key, value in entries]
        blocks.append("\n".join(lines))
    return "\n\n".join(blocks) + "\n"


def _strip_comment(line: str) -> str:
    if line.lstrip().startswith(";"):
        return ""
    for position, char in enumerate(line):
        if char == ";" and position > 0 and line[position - 1].isspace():
            return line[:position]
    return line


def _parse_header(content: str, number: int, path: Path) -> IniSection:
    if not content.endswith("]") or len(content) < 3:
        raise DictionaryError(path, number, "-", f"malformed section header {content!r}")
    name = content[1:-1].strip()
    if not name or "[" in name or "]" in name:
        raise DictionaryError(path, number, "-", f"malformed section header {content!r}")
    return IniSection(name, number)
