"""Names that become directory or file names (projects, axes, motors).

Projects travel between Linux and Windows machines (archives, git), so a name must be valid on both: no path
separators, no reserved device names, no trailing dot or space, and uniqueness is checked without regard to case.
"""

from __future__ import annotations

import re

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
