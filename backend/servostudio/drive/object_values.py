"""Typed values of dictionary objects: user input → raw value, raw bytes → value with unit, enum label and bits.

Raw values are what travels on the bus; physical values are ``raw * Scale + Offset`` in the object's unit.  Text
input (CLI, REST) may be a decimal or ``0x`` number, an enumeration label, or text for string objects.
"""

from __future__ import annotations

from dataclasses import dataclass

from servostudio.errors import InvalidInput
from servostudio.od.datatypes import DataType, EncodingError, decode
from servostudio.od.model import OutOfRange, Variable, WrongType

Raw = int | float | str | bytes


class ValueInputError(InvalidInput):
    """User input that cannot become a value of the object; the message names the object."""


def parse_input(variable: Variable, value: object, physical: bool = False) -> Raw:
    """Turn user input into the raw value to write, and check it against type and limits."""
    raw = _to_raw(variable, value, physical)
    try:
        variable.check(raw)
    except (OutOfRange, WrongType) as error:
        raise ValueInputError(str(error)) from None
    return raw


def _to_raw(variable: Variable, value: object, physical: bool) -> Raw:
    data_type = variable.data_type
    if data_type.is_text:
        return value if isinstance(value, str) else str(value)
    if data_type.is_binary:
        if isinstance(value, (bytes, bytearray)):
            return bytes(value)
        try:
            return bytes.fromhex(str(value))
        except ValueError:
            raise ValueInputError(f"{variable.label}: {data_type.name} needs hex bytes, got {value!r}") from None
    if isinstance(value, str):
        value = _parse_text(variable, value)
    if isinstance(value, bool):
        value = int(value)
    if not isinstance(value, (int, float)):
        raise ValueInputError(f"{variable.label}: {data_type.name} needs a number, got {value!r}")
    if physical and (variable.scale != 1.0 or variable.offset != 0.0):
        return variable.from_physical(float(value))
    if data_type.is_integer or data_type.is_time:
        if isinstance(value, float):
            if not value.is_integer():
                raise ValueInputError(f"{variable.label}: {data_type.name} needs an integer, got {value}")
            return int(value)
        return value
    return float(value)


def _parse_text(variable: Variable, text: str) -> int | float:
    stripped = text.strip()
    for key, label in variable.enum.items():
        if label.casefold() == stripped.casefold():
            return key
    try:
        return int(stripped, 0)
    except ValueError:
        pass
    try:
        return float(stripped)
    except ValueError:
        choices = f"; one of: {', '.join(variable.enum.values())}" if variable.enum else ""
        raise ValueInputError(f"{variable.label}: {text!r} is not a number{choices}") from None


def decode_raw(variable: Variable, data: bytes) -> Raw:
    """Bytes from the drive → raw value; devices that answer with a wider integer are accepted (extra bytes zero)."""
    size = variable.data_type.size
    if size is not None and len(data) > size and not any(data[size:]):
        data = data[:size]
    try:
        return decode(variable.data_type, data)
    except EncodingError as error:
        raise ValueInputError(f"{variable.label}: drive answered {data.hex(' ')}: {error}") from None


@dataclass(frozen=True)
class ObjectValue:
    """A value read from (or written to) a drive, with everything a client needs to show it."""

    node: int
    variable: Variable
    raw: Raw

    @property
    def physical(self) -> Raw:
        var = self.variable
        if isinstance(self.raw, (int, float)) and not isinstance(self.raw, bool) and (var.scale != 1.0 or var.offset):
            return var.to_physical(self.raw)
        return self.raw

    @property
    def text(self) -> str:
        """What a terminal shows: the enumeration label, else the physical value with its unit."""
        if isinstance(self.raw, int) and self.raw in self.variable.enum:
            return self.variable.enum[self.raw]
        value = self.physical  # bytes stay bytes
        if isinstance(value, bytes):
            return value.hex(" ")
        return f"{value} {self.variable.unit}".strip() if self.variable.unit else str(value)

    def bits(self) -> list[dict[str, object]]:
        if not isinstance(self.raw, int):
            return []
        return [
            {"name": field.name, "first": field.first, "last": field.last, "value": field.extract(self.raw)}
            for field in self.variable.bits
        ]

    def as_dict(self) -> dict[str, object]:
        var = self.variable
        raw = self.raw.hex() if isinstance(self.raw, bytes) else self.raw
        physical = self.physical
        return {
            "node": self.node,
            "index": var.index,
            "sub": var.subindex,
            "name": var.name,
            "label": var.label,
            "data_type": DataType(var.data_type).name,
            "access": var.access.value,
            "raw": raw,
            "physical": physical.hex() if isinstance(physical, bytes) else physical,
            "unit": var.unit,
            "text": self.text,
            "bits": self.bits(),
        }
