"""Typed parameter values: what a user types, what the dictionary checks, what the object file stores.

The object file (DRIVEPAR.TXT / USER_PAR.TXT) holds integers and text only. REAL32/REAL64 values are stored as their
IEEE-754 bit pattern (an unsigned integer), the same convention the EDS uses for REAL defaults; OCTET_STRING and DOMAIN
values have no object-file spelling and are not editable offline.
"""

from __future__ import annotations

import struct

from servostudio.errors import InvalidInput
from servostudio.formats.numbers import parse_integer
from servostudio.od import DataType, Variable

Value = int | float | str | bytes


class BadValue(InvalidInput):
    """A value cannot be interpreted for an object; the message names the object."""


def parse_text(variable: Variable, text: str) -> Value:
    """Interpret user input (CLI argument, form field) as a value of ``variable``.

    Integers: decimal or ``0x`` hex, or the name of one of the object's enumeration values. Floats: decimal.
    Strings: the text itself.
    """
    data_type = variable.data_type
    if data_type.is_text:
        return text
    if data_type.is_float:
        try:
            return float(text)
        except ValueError:
            raise BadValue(f"{variable.label}: {text!r} is not a number") from None
    if data_type.is_binary:
        raise BadValue(f"{variable.label}: {data_type.name} values cannot be edited offline")
    value = parse_integer(text.strip())
    if value is not None:
        return value
    for number, label in variable.enum.items():
        if label.casefold() == text.strip().casefold():
            return number
    choices = f" or one of: {', '.join(variable.enum.values())}" if variable.enum else ""
    raise BadValue(f"{variable.label}: {text!r} is not a decimal or 0x hex integer{choices}")


def coerce(variable: Variable, value: object) -> Value:
    """Accept JSON values (REST bodies): numbers as numbers, strings parsed like user input."""
    if isinstance(value, str) and not variable.data_type.is_text:
        return parse_text(variable, value)
    if isinstance(value, float) and variable.data_type.is_integer and value.is_integer():
        return int(value)
    return value  # type: ignore[return-value]


def normalize(variable: Variable, value: Value | None) -> Value | None:
    """Bring a value to what the drive would hold, so comparisons are exact (REAL32 rounds to single precision)."""
    if value is None:
        return None
    if variable.data_type is DataType.REAL32 and isinstance(value, (int, float)):
        return struct.unpack("<f", struct.pack("<f", float(value)))[0]
    if variable.data_type.is_float and isinstance(value, int):
        return float(value)
    return value


def to_file_value(variable: Variable, value: Value) -> int | str:
    data_type = variable.data_type
    if data_type.is_float:
        fmt = "<f" if data_type is DataType.REAL32 else "<d"
        return int.from_bytes(struct.pack(fmt, float(value)), "little")
    if data_type.is_binary:
        raise BadValue(f"{variable.label}: {data_type.name} values have no object-file form")
    return value  # type: ignore[return-value]


def from_file_value(variable: Variable, stored: int | str) -> Value:
    """Inverse of :func:`to_file_value`; raises ``BadValue`` when the stored value cannot be of this type."""
    data_type = variable.data_type
    if data_type.is_text:
        if not isinstance(stored, str):
            raise BadValue(f"{variable.label}: expected text, found number {stored}")
        return stored
    if not isinstance(stored, int):
        raise BadValue(f"{variable.label}: expected a number, found text {stored!r}")
    if data_type.is_float:
        size = data_type.size or 4
        if not 0 <= stored < 1 << (8 * size):
            raise BadValue(f"{variable.label}: {stored} is not a {8 * size}-bit IEEE-754 bit pattern")
        fmt = "<f" if data_type is DataType.REAL32 else "<d"
        return struct.unpack(fmt, stored.to_bytes(size, "little"))[0]
    if data_type.is_binary:
        raise BadValue(f"{variable.label}: {data_type.name} values have no object-file form")
    return stored


def display(variable: Variable, value: Value | None) -> str | int | float | None:
    """JSON-friendly form: bytes as hex, everything else unchanged."""
    if isinstance(value, bytes):
        return value.hex()
    return value
