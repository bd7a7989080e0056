"""Names that become directory or file names (projects, axes, motors).

Projects travel between Linux and Windows machines (archives, git), so a name must be valid on both: no path
separators, no reserved device names, no trailing dot or space, and uniqueness is checked without regard to case.
"""

from __future__ import annotations

import re
from datetime import datetime
from pathlib import Path

from servostudio.services.projects.errors import InvalidName

_ALLOWED = re.compile(r"[A-Za-z0-9][A-Za-z0-9 _.+-]{0,63}")
_WINDOWS_RESERVED = {"CON", "PRN", "AUX", "NUL"} | {f"COM{i}" for i in range(1, 10)} | {f"LPT{i}" for i in range(1, 10)}


def check_name(name: str, what: str) -> str:
    """Return ``name`` if it is safe as a directory name on every platform, else raise :class:`InvalidName`."""
    if not isinstance(name, str) or not _ALLOWED.fullmatch(name):
        raise InvalidName(
            f"{what} name {name!r} is not allowed: use 1-64 characters, letters, digits, space, '_', '.', '+', '-',"
            " starting with a letter or digit"
        )
    if name.endswith((" ", ".")):
        raise InvalidName(f"{what} name {name!r} must not end with a space or a dot")
    if name.split(".")[0].upper() in _WINDOWS_RESERVED:
        raise InvalidName(f"{what} name {name!r} is a reserved device name on Windows")
    return name


def same_name(a: str, b: str) -> bool:
    """Names clash when they differ only by case (case-insensitive file systems)."""
    return a.casefold() == b.casefold()


def is_valid_name(name: str) -> bool:
    try:
        check_name(name, "")
    except InvalidName:
        return False
    return True


def timestamp_name(directory: Path, time: str, fallback: str) -> str:
    """A record's file stem from its ISO time (``2026-12-02 05-01-02``), numbered when that name is taken.

    Captures and frequency responses are saved under the time they were measured; ``fallback`` names a record whose
    time does not parse.
    """
    try:
        stamp = datetime.fromisoformat(time.replace("Z", "+00:00")).strftime("%Y-%m-%d %H-%M-%S")
    except ValueError:
        stamp = fallback
    candidates = [stamp, *(f"{stamp}-{number}" for number in range(2, 1000))]
    return next(candidate for candidate in candidates if not name_taken(directory, candidate))


def name_taken(directory: Path, name: str) -> bool:
    """Whether a record (its ``.json`` sidecar) of that name, in any case, is already in ``directory``."""
    return directory.is_dir() and any(same_name(path.stem, name) for path in directory.glob("*.json"))
