"""Integer literals as the drive's text files write them: decimal or ``0x`` hexadecimal, optionally signed.

Both the object file and SEQUENCE.TXT use the same rule ("decimal or hexadecimal, preceded by 0x"), so one
parser serves both. ``int(text, 0)`` does not fit: it rejects decimal leading zeros (``007``) and accepts ``0o``/``0b``
prefixes and underscores, which the drive does not know.
"""

from __future__ import annotations

import re

_INTEGER = re.compile(r"([+-]?)(?:0[xX]([0-9a-fA-F]+)|([0-9]+))")


def parse_integer(text: str) -> int | None:
    """Return the value of a decimal or ``0x`` hex literal, or None when ``text`` is not one."""
    match = _INTEGER.fullmatch(text)
    if match is None:
        return None
    sign, hex_digits, decimal_digits = match.groups()
    value = int(hex_digits, 16) if hex_digits is not None else int(decimal_digits, 10)
    return -value if sign == "-" else value
