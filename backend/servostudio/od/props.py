"""Companion `.props` file: what an EDS cannot say (unit, scale, save type, group, enumerations, bit fields, ...).

Same INI syntax and section names as the EDS (`[6041]`, `[60F9sub2]`). Keys of an object section `[xxxx]` apply to
all its sub-entries unless the `[xxxxsubN]` section sets the key itself; the value-describing keys (Unit, Scale,
Offset, Enum.*, Bit.*, Bits.*, Pointer) skip sub-index 0 of an ARRAY/RECORD, which only counts entries. A sub
section's Enum.* (or Bit.*/Bits.*) keys replace the inherited set as a whole. See docs/eds.md.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Any

from servostudio.od.datatypes import DataType
from servostudio.od.eds_values import ValueSyntaxError, parse_integer
from servostudio.od.ini import IniEntry, IniFile, IniSection
from servostudio.od.model import BitField, DictionaryError, DictObject, ObjectKind, SaveType, Variable

_OBJECT = re.compile(r"^(?P<index>[0-9A-F]{4})(?:sub(?P<sub>[0-9A-F]{1,2}))?$", re.IGNORECASE)
_ENUM = re.compile(r"^enum\.(?P<value>.+)$", re.IGNORECASE)
_BIT = re.compile(r"^bit\.(?P<bit>\d+)$", re.IGNORECASE)
_BITS = re.compile(r"^bits\.(?P<first>\d+)-(?P<last>\d+)$", re.IGNORECASE)
_TEXT_KEYS = frozenset({"group", "description", "unit", "reference"})
_VALUE_KEYS = frozenset({"unit", "scale", "offset", "pointer", "enum", "bits"})
_Fail = Callable[[str], DictionaryError]  # builds the error for the entry being read, from a reason


@dataclass
class _Props:
    """Properties read from one section; None = not set there (so inheritance applies)."""

    section: IniSection
    values: dict[str, object] = field(default_factory=dict)
    enum: dict[int, str] | None = None
    bits: list[tuple[BitField, int]] | None = None


def apply_props(ini: IniFile, objects: dict[int, DictObject]) -> dict[int, DictObject]:
    """Return the objects with the properties of `ini` applied; raises DictionaryError on any bad section or key."""
    by_object: dict[int, _Props] = {}
    by_sub: dict[tuple[int, int], _Props] = {}
    for section in ini:
        index, sub = _target(ini, section, objects)
        props = _read_section(ini, section)
        if sub is None:
            by_object[index] = props
        else:
            by_sub[(index, sub)] = props
    result = {}
    for index, obj in objects.items():
        object_props = by_object.get(index)
        subs = {
            sub: _apply(ini, var, object_props, by_sub.get((index, sub)), inherit_values=_inherits_values(obj, sub))
            for sub, var in obj.subs.items()
        }
        group = str(object_props.values.get("group", "")) if object_props else ""
        result[index] = replace(obj, group=group, subs=subs)
    return result


def _inherits_values(obj: DictObject, sub: int) -> bool:
    return obj.kind is ObjectKind.VAR or sub != 0


def _target(ini: IniFile, section: IniSection, objects: dict[int, DictObject]) -> tuple[int, int | None]:
    match = _OBJECT.match(section.name)
    if not match:
        raise DictionaryError(ini.path, section.line, section.name, "not an object section ([xxxx] or [xxxxsubN])")
    index = int(match["index"], 16)
    if index not in objects:
        raise DictionaryError(ini.path, section.line, section.name, f"object 0x{index:04X} does not exist in the EDS")
    if match["sub"] is None:
        return index, None
    sub = int(match["sub"], 16)
    if sub not in objects[index].subs:
        raise DictionaryError(ini.path, section.line, section.name, f"0x{index:04X} has no sub-index {sub}")
    return index, sub


def _read_section(ini: IniFile, section: IniSection) -> _Props:
    props = _Props(section)
    for entry in section:
        key = entry.key.lower()

        def fail(reason: str, entry: IniEntry = entry) -> DictionaryError:
            return DictionaryError(ini.path, entry.line, section.name, reason)

        if key in _TEXT_KEYS:
            props.values[key] = entry.value
        elif key in ("scale", "offset"):
            props.values[key] = _real(entry.value, key, nonzero=key == "scale", fail=fail)
        elif key == "savetype":
            try:
                props.values[key] = SaveType(entry.value.upper())
            except ValueError:
                raise fail(f"SaveType {entry.value!r} is not DRIVEPAR|USER_PAR|NONE") from None
        elif key == "pointer":
            if entry.value not in ("0", "1"):
                raise fail(f"Pointer must be 0 or 1, not {entry.value!r}")
            props.values[key] = entry.value == "1"
        elif match := _ENUM.match(entry.key):
            _add_enum(props, match["value"], entry.value, fail)
        elif match := _BIT.match(entry.key):
            _add_bits(props, int(match["bit"]), int(match["bit"]), entry.value, entry.line, fail)
        elif match := _BITS.match(entry.key):
            _add_bits(props, int(match["first"]), int(match["last"]), entry.value, entry.line, fail)
        else:
            raise fail(f"unknown key {entry.key!r}")
    return props


def _real(text: str, key: str, nonzero: bool, fail: _Fail) -> float:
    try:
        value = float(text)
    except ValueError:
        raise fail(f"{key} {text!r} is not a number") from None
    if not math.isfinite(value) or (nonzero and value == 0):
        raise fail(f"{key} {text!r} must be a finite{' non-zero' if nonzero else ''} number")
    return value


def _add_enum(props: _Props, value_text: str, name: str, fail: _Fail) -> None:
    try:
        value = parse_integer(value_text)
    except ValueSyntaxError as exc:
        raise fail(f"bad Enum key: {exc}") from None
    if not name:
        raise fail(f"Enum.{value_text} has no name")
    props.enum = props.enum if props.enum is not None else {}
    if value in props.enum:
        raise fail(f"Enum value {value} is given twice")
    props.enum[value] = name


def _add_bits(props: _Props, first: int, last: int, name: str, line: int, fail: _Fail) -> None:
    if first > last:
        raise fail(f"bit range {first}-{last} is reversed")
    if not name:
        raise fail(f"bit {first}-{last} has no name")
    props.bits = props.bits if props.bits is not None else []
    for other, _ in props.bits:
        if first <= other.last and other.first <= last:
            raise fail(f"bits {first}-{last} overlap bits {other.first}-{other.last} ({other.name})")
    props.bits.append((BitField(first, last, name), line))


def _apply(ini: IniFile, var: Variable, inherited: _Props | None, own: _Props | None, inherit_values: bool) -> Variable:
    layers = [p for p in (inherited, own) if p is not None]
    if not layers:
        return var
    changes: dict[str, Any] = {}  # Variable field name -> value; `replace` rejects an unknown name
    enum_source: tuple[IniSection, dict[int, str]] | None = None
    bits_source: tuple[IniSection, list[tuple[BitField, int]]] | None = None
    for layer in layers:
        value_keys_apply = layer is own or inherit_values
        for key, value in layer.values.items():
            if key in _VALUE_KEYS and not value_keys_apply:
                continue
            changes[{"savetype": "save_type", "pointer": "is_pointer"}.get(key, key)] = value
        if value_keys_apply and layer.enum is not None:
            enum_source = (layer.section, layer.enum)
        if value_keys_apply and layer.bits is not None:
            bits_source = (layer.section, layer.bits)
    if enum_source is not None:
        _check_enum(ini, var, *enum_source)
        changes["enum"] = dict(enum_source[1])
    if bits_source is not None:
        _check_bits(ini, var, *bits_source)
        changes["bits"] = tuple(sorted((b for b, _ in bits_source[1]), key=lambda b: b.first))
    if changes.get("is_pointer") and var.data_type is not DataType.UNSIGNED32:
        section = layers[-1].section
        raise DictionaryError(
            ini.path, section.line_of("Pointer"), section.name, f"Pointer needs UNSIGNED32, not {var.data_type.name}"
        )
    return replace(var, **changes)


def _check_enum(ini: IniFile, var: Variable, section: IniSection, enum: dict[int, str]) -> None:
    for value in enum:
        if not _holds(var.data_type, value):
            line = next(e.line for e in section if _enum_value(e.key) == value)
            raise DictionaryError(
                ini.path,
                line,
                section.name,
                f"Enum value {value} does not fit 0x{var.index:04X},{var.subindex} ({var.data_type.name})",
            )


def _holds(data_type: DataType, value: int) -> bool:
    """Whether an enumeration value fits the object: only integer objects have enumerations."""
    if not data_type.is_integer:
        return False
    low, high = data_type.integer_range
    return low <= value <= high


def _enum_value(key: str) -> int | None:
    """The value an ``Enum.<value>`` key names; None for any other key."""
    match = _ENUM.match(key)
    if match is None:
        return None
    try:
        return parse_integer(match["value"])
    except ValueSyntaxError:
        return None


def _check_bits(ini: IniFile, var: Variable, section: IniSection, bits: list[tuple[BitField, int]]) -> None:
    width = var.data_type.bits if var.data_type.is_integer else None
    for bit_field, line in bits:
        if width is None or bit_field.last >= width:
            raise DictionaryError(
                ini.path,
                line,
                section.name,
                f"bit {bit_field.last} does not exist in 0x{var.index:04X},{var.subindex} ({var.data_type.name})",
            )
