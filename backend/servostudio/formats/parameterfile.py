"""TTAPAR.TXT: the parameter backup of a PROFIBUS drive (the TTA-PRO), beside the XtrapulsPac's DRIVEPAR.TXT.

The object file's syntax (``formats/objectfile.py``: one ``address=value`` per line, ``;`` comments, lines that do
not begin with a digit ignored, an address assigned once) with the address a PROFIBUS drive has: ``PNU,IND``, the
parameter number 1..1999 and its index 0..255 (0 for a plain PNU), and integer values only (every PNU is a word
or a double word). The canonical form, which backups write, spells both numbers in decimal, sorted, so two backups
of the same drive are byte-identical and ``700,0=4`` reads as the manual writes "PNU 700". The grammar is in
docs/profibus.md §10.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable

from servostudio.formats.objectfile import EntryValidator, ObjectEntry, format_object_file, parse_object_file
from servostudio.formats.textfile import split_lines, write_text_atomic

PARAMETER_FILE = "TTAPAR.TXT"
PNUS = range(1, 2000)
INDICES = range(256)


def is_parameter_file(name: str) -> bool:
    """TTAPAR.TXT (any case, ``node5_TTAPAR.TXT`` too) is in this syntax; every other parameter file of a drive,
    DRIVEPAR.TXT and USER_PAR.TXT, in the object file's."""
    return name.upper().endswith(PARAMETER_FILE)


def parse_drive_file(
    name: str, text: str, file: str = "<string>", validate: EntryValidator | None = None
) -> list[ObjectEntry]:
    """A drive's parameter file called ``name`` read in its syntax (`is_parameter_file`)."""
    return (parse_parameter_file if is_parameter_file(name) else parse_object_file)(text, file, validate)


def format_drive_file(name: str, entries: Iterable[ObjectEntry], header: str | None = None) -> str:
    """A drive's parameter file called ``name`` in the canonical form of its syntax."""
    return (format_parameter_file if is_parameter_file(name) else format_object_file)(entries, header)


def parse_parameter_file(
    text: str, file: str = "<string>", validate: EntryValidator | None = None
) -> list[ObjectEntry]:
    """Parse TTAPAR.TXT text into its entries (index = PNU, sub = IND); ObjectFileError ``FILE:LINE: reason`` on
    the first bad line."""

    def checked(entry: ObjectEntry) -> str | None:
        problem = _problem(entry)
        if problem is None and validate is not None:
            return validate(entry)
        return problem

    return parse_object_file(text, file, checked, spelled=lambda pnu, ind: f"PNU {pnu},{ind}")


def by_pnu(entry: ObjectEntry) -> tuple[int, int]:
    return entry.index, entry.sub


def by_ind(entry: ObjectEntry) -> tuple[int, int]:
    """IND first: the lines of one sequence of a sequence table (IND = its number) stand together."""
    return entry.sub, entry.index


def format_parameter_file(
    entries: Iterable[ObjectEntry], header: str | None = None, order: Callable[[ObjectEntry], tuple[int, int]] = by_pnu
) -> str:
    """The canonical text: header comments, then ``PNU,IND=value`` in decimal sorted by ``order`` ((PNU, IND) by
    default); ValueError for an entry the reader would refuse."""
    lines = [f"; {text}" if text.strip() else ";" for text in split_lines(header)] if header else []
    previous: tuple[int, int] | None = None
    for entry in sorted(entries, key=order):
        problem = _problem(entry) or ("assigned twice" if (entry.index, entry.sub) == previous else None)
        if problem is not None:
            raise ValueError(f"PNU {entry.index},{entry.sub}: {problem}")
        previous = (entry.index, entry.sub)
        lines.append(f"{entry.index},{entry.sub}={entry.value}")
    return "".join(line + "\n" for line in lines)


def write_parameter_file(
    path: str | os.PathLike[str], entries: Iterable[ObjectEntry], header: str | None = None
) -> None:
    """Write the canonical text atomically (the old file stays intact if anything fails)."""
    write_text_atomic(path, format_parameter_file(entries, header))


def _problem(entry: ObjectEntry) -> str | None:
    if entry.index not in PNUS:
        return f"PNU {entry.index} outside 1..1999"
    if entry.sub not in INDICES:
        return f"IND {entry.sub} outside 0..255"
    if not isinstance(entry.value, int):
        return f"value {entry.value!r} is not an integer (a PNU holds a word or a double word)"
    return None
