"""Parsing of the value texts found in EDS files (DefaultValue, LowLimit, HighLimit) per CiA 306.

- Integers: decimal (`-12`), hexadecimal (`0x1F`), octal with a leading zero (`017`), optional sign.
- `$NODEID` terms (integer types only, DefaultValue only): `$NODEID`, `$NODEID+0x180`, `0x180+$NODEID`
  (case-insensitive). The constant part is returned together with a flag.
- REAL32/REAL64: a hexadecimal text is the IEEE-754 bit pattern (what lely's dcf-tools expects, e.g. `0x3F800000`
  is 1.0); any other text is a decimal number (`1.5`, `-2e-3`).
- TIME_OF_DAY / TIME_DIFFERENCE: "days ms" (`365 43200000`, as Lely's dcf-tools read and write them) or one integer
  `days << 32 | ms`.
- VISIBLE_STRING / UNICODE_STRING: the text itself. OCTET_STRING / DOMAIN: hexadecimal digits, two per byte
  (whitespace ignored), e.g. `0102AB`.
"""

from __future__ import annotations

import re
import struct

from servostudio.errors import InvalidInput
from servostudio.od.datatypes import DataType

_NODE_ID = re.compile(r"^\s*\$nodeid\s*(?:\+\s*(?P<after>.+?))?\s*$|^\s*(?P<before>.+?)\s*\+\s*\$nodeid\s*$", re.I)


#: CiA 301 TIME_OF_DAY / TIME_DIFFERENCE: 16-bit days and 28-bit milliseconds
TIME_MAX_DAYS = 0xFFFF
TIME_MAX_MS = (1 << 28) - 1


class ValueSyntaxError(InvalidInput):
    """A value text cannot be read; the message is the reason, without location."""


def parse_integer(text: str) -> int:
    """Decimal, 0x-hexadecimal or 0-octal integer with an optional sign."""
    body = text.strip()
    sign = 1
    if body and body[0] in "+-":
        sign = -1 if body[0] == "-" else 1
        body = body[1:].strip()
    try:
        if body.lower().startswith("0x"):
            return sign * int(body[2:], 16)
        if len(body) > 1 and body.startswith("0"):
            return sign * int(body[1:], 8)
        if body.isdigit():
            return sign * int(body, 10)
    except ValueError:
        pass
    raise ValueSyntaxError(f"{text!r} is not an integer (decimal, 0x hexadecimal or 0 octal)")


def parse_value(data_type: DataType, text: str, allow_node_id: bool = False) -> tuple[int | float | str | bytes, bool]:
    """Read `text` as a value of `data_type`; returns (value, uses_node_id) where value excludes the $NODEID term."""
    if data_type.is_text:
        return text, False
    if data_type.is_binary:
        return _parse_hex_bytes(text), False
    return parse_number(data_type, text, allow_node_id)


def parse_number(data_type: DataType, text: str, allow_node_id: bool = False) -> tuple[int | float, bool]:
    """`parse_value` for the numeric, BOOLEAN and TIME types, typed as a number for the range checks that follow."""
    if data_type.is_float:
        return _parse_float(data_type, text), False
    if data_type.is_time:
        return _parse_time(text), False
    node_id = _NODE_ID.match(text)
    if node_id and "$" in text:
        if not allow_node_id:
            raise ValueSyntaxError(f"$NODEID is not allowed here ({text!r})")
        constant = node_id["after"] or node_id["before"]
        return (parse_integer(constant) if constant else 0), True
    return parse_integer(text), False


def _parse_float(data_type: DataType, text: str) -> float:
    body = text.strip()
    if body.lower().lstrip("+-").startswith("0x"):
        pattern = parse_integer(body)
        size = data_type.fixed_size
        if not 0 <= pattern < 1 << (8 * size):
            raise ValueSyntaxError(f"{text!r} is not a {size * 8}-bit IEEE-754 bit pattern")
        fmt = "<f" if data_type is DataType.REAL32 else "<d"
        return struct.unpack(fmt, pattern.to_bytes(size, "little"))[0]
    try:
        return float(body)
    except ValueError:
        raise ValueSyntaxError(f"{text!r} is not a number") from None


def _parse_time(text: str) -> int:
    """TIME_OF_DAY / TIME_DIFFERENCE as "days ms" (two integers, as Lely's tools write them) or as the one
    integer ``days << 32 | ms`` of our own model; both end as that integer."""
    parts = text.split()
    if len(parts) != 2:
        return parse_integer(text)
    days, ms = (parse_integer(part) for part in parts)
    if not 0 <= days <= TIME_MAX_DAYS or not 0 <= ms <= TIME_MAX_MS:
        raise ValueSyntaxError(f"{text!r}: days must be 0..{TIME_MAX_DAYS} and milliseconds 0..{TIME_MAX_MS}")
    return days << 32 | ms


def _parse_hex_bytes(text: str) -> bytes:
    digits = "".join(text.split())
    try:
        return bytes.fromhex(digits)
    except ValueError:
        raise ValueSyntaxError(f"{text!r} is not a sequence of hexadecimal byte values") from None


def float_bit_pattern(data_type: DataType, value: float) -> str:
    """The EDS spelling of a REAL value that both our reader and dcf-tools understand."""
    fmt = "<f" if data_type is DataType.REAL32 else "<d"
    digits = data_type.fixed_size * 2
    return f"0x{int.from_bytes(struct.pack(fmt, value), 'little'):0{digits}X}"


def time_text(value: int) -> str:
    """The EDS spelling of a TIME_OF_DAY / TIME_DIFFERENCE value ``days << 32 | ms``: "days ms", the one form both
    our reader and dcf-tools read."""
    return f"{value >> 32} {value & 0xFFFFFFFF}"
