"""Load a PROFIBUS parameter list (`eds/<device>.pnu`) into a `ParameterDictionary`, rejecting malformed files.

The file uses the INI syntax of the EDS (`od/ini.py`): a `[Device]` section and one `[PNU<n>]` section per
parameter; docs/profibus.md §2 lists the keys. Every rejection is a `DictionaryError` whose text is
`FILE:LINE: [SECTION] REASON`, the line of the offending key (or of the section header when a key is missing).
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from pathlib import Path
from typing import TypeVar

from servostudio.od.datatypes import DataType
from servostudio.od.eds_values import ValueSyntaxError, parse_integer
from servostudio.od.ini import IniFile, IniSection, parse_ini, read_ini
from servostudio.od.library import BUILTIN_EDS_DIR
from servostudio.od.model import Access, BitField, DictionaryError
from servostudio.od.pnu_model import Parameter, ParameterDictionary, Persistence

PNU_RANGE = range(1, 2000)
"""PKE bits 0..10 carry the PNU; the manual allows 1..1999 (L277-285)."""
INDEX_RANGE = range(256)
"""IND is PKW byte 3."""
TYPES = {"U16": DataType.UNSIGNED16, "I16": DataType.INTEGER16, "U32": DataType.UNSIGNED32, "I32": DataType.INTEGER32}
ACCESS = {"ro": Access.RO, "rw": Access.RW, "wo": Access.WO}
FLAGS = {"yes": True, "no": False}
_Choice = TypeVar("_Choice")
_SECTION = re.compile(r"^PNU(?P<pnu>\d{1,4})$", re.IGNORECASE)
_RANGE = re.compile(r"^\s*(?P<first>\d+)\s*\.\.\s*(?P<last>\d+)\s*$")
_ENUM = re.compile(r"^enum\.(?P<value>.+)$", re.IGNORECASE)
_BIT = re.compile(r"^bit\.(?P<bit>\d+)$", re.IGNORECASE)
_BITS = re.compile(r"^bits\.(?P<first>\d+)-(?P<last>\d+)$", re.IGNORECASE)
_DEVICE_KEYS = frozenset({"name", "vendor", "identnumber", "manual"})
_PARAMETER_KEYS = frozenset(
    {
        "name",
        "type",
        "access",
        "save",
        "min",
        "max",
        "default",
        "unit",
        "scale",
        "group",
        "description",
        "reference",
        "derived",
        "index",
        "procedure",
        "repeatable",
        "disabled",
    }
)


def load_parameter_list(path: Path) -> ParameterDictionary:
    """Read a `.pnu` file; the device key is its name without suffix, lower-cased."""
    return _ListReader(read_ini(Path(path))).dictionary()


def parse_parameter_list(text: str, path: Path) -> ParameterDictionary:
    """`load_parameter_list` on text already in memory (`path` names it in error messages)."""
    return _ListReader(parse_ini(text, Path(path))).dictionary()


def builtin_parameter_list(device: str = "ttapro") -> ParameterDictionary:
    """The built-in parameter list `eds/<device>.pnu`."""
    return load_parameter_list(BUILTIN_EDS_DIR / f"{device}.pnu")


class _ListReader:
    """Checks one parsed file; each method reads one section or one key and names its line when it refuses."""

    def __init__(self, ini: IniFile) -> None:
        self.ini = ini

    def error(self, section: IniSection, key: str, reason: str) -> DictionaryError:
        return DictionaryError(self.ini.path, section.line_of(key), section.name, reason)

    def dictionary(self) -> ParameterDictionary:
        device = self._device_section()
        parameters = [self._parameter(section) for section in self.ini if section is not device]
        name = device.get("Name") or self.ini.path.stem
        ident = self._integer(device, "IdentNumber", range(0x10000))
        return ParameterDictionary(self.ini.path.stem.lower(), name, ident, self.ini.path, parameters)

    def _device_section(self) -> IniSection:
        device = self.ini.section("Device")
        if device is None:
            raise DictionaryError(self.ini.path, 1, "Device", "section [Device] is missing")
        self._check_keys(device, _DEVICE_KEYS)
        if "IdentNumber" not in device:
            raise self.error(device, "IdentNumber", "IdentNumber is missing")
        return device

    def _check_keys(self, section: IniSection, allowed: frozenset[str], patterns: bool = False) -> None:
        """Every key must be known: a typing error in a key would otherwise silently drop an attribute."""
        for entry in section:
            key = entry.key.casefold()
            named = patterns and (_ENUM.match(key) or _bit_span(key) is not None)
            if key not in allowed and not named:
                raise DictionaryError(self.ini.path, entry.line, section.name, f"unknown key {entry.key!r}")

    # -- one parameter ------------------------------------------------------------------------------------------

    def _parameter(self, section: IniSection) -> Parameter:
        pnu = self._pnu(section)
        self._check_keys(section, _PARAMETER_KEYS, patterns=True)
        data_type = self._choice(section, "Type", TYPES)
        access = self._choice(section, "Access", ACCESS)
        low, high = self._limits(section, data_type)
        indices = self._indices(section)
        return Parameter(
            pnu=pnu,
            name=self._required(section, "Name"),
            data_type=data_type,
            access=access,
            persistence=self._persistence(section),
            low=low,
            high=high,
            defaults=self._defaults(section, data_type, low, high, indices),
            unit=section.get("Unit", "") or "",
            scale=self._scale(section),
            group=section.get("Group", "") or "",
            description=section.get("Description", "") or "",
            reference=section.get("Reference", "") or "",
            derived=section.get("Derived", "") or "",
            indices=indices,
            procedure=self._flag(section, "Procedure"),
            repeatable=self._repeatable(section),
            disabled_only=self._flag(section, "Disabled"),
            enum=self._enum(section, data_type),
            bits=self._bits(section, data_type),
        )

    def _pnu(self, section: IniSection) -> int:
        match = _SECTION.match(section.name)
        if match is None:
            raise DictionaryError(self.ini.path, section.line, section.name, "section must be [Device] or [PNU<n>]")
        pnu = int(match["pnu"])
        if pnu not in PNU_RANGE:
            raise DictionaryError(self.ini.path, section.line, section.name, f"PNU {pnu} is outside 1..1999")
        return pnu

    def _required(self, section: IniSection, key: str) -> str:
        value = section.get(key)
        if not value:
            raise self.error(section, key, f"{key} is missing")
        return value

    def _choice(self, section: IniSection, key: str, choices: Mapping[str, _Choice]) -> _Choice:
        text = self._required(section, key)
        for name, choice in choices.items():
            if name.casefold() == text.casefold():
                return choice
        raise self.error(section, key, f"{key} {text!r} is not one of {', '.join(choices)}")

    def _persistence(self, section: IniSection) -> Persistence:
        text = section.get("Save", "RAM") or "RAM"
        try:
            return Persistence(text.upper())
        except ValueError:
            raise self.error(section, "Save", f"Save {text!r} is not one of E, S, RAM") from None

    def _repeatable(self, section: IniSection) -> bool:
        """Only a procedure can be run again: a value write is repeated after a lost exchange anyway."""
        repeatable = self._flag(section, "Repeatable")
        if repeatable and not self._flag(section, "Procedure"):
            raise self.error(section, "Repeatable", "Repeatable=yes needs Procedure=yes")
        return repeatable

    def _flag(self, section: IniSection, key: str) -> bool:
        text = (section.get(key, "no") or "no").lower()
        if text not in FLAGS:
            raise self.error(section, key, f"{key} must be yes or no, not {text!r}")
        return FLAGS[text]

    def _integer(
        self, section: IniSection, key: str, allowed: range | None = None, text: str | None = None, label: str = ""
    ) -> int:
        """An integer value of `key` (or `text` found in it), inside `allowed`; `label` names it in messages."""
        text = section.get(key, "") if text is None else text
        label = label or key
        try:
            value = parse_integer(text or "")
        except ValueSyntaxError as exc:
            raise self.error(section, key, f"{label}: {exc}") from None
        if allowed is not None and value not in allowed:
            raise self.error(section, key, f"{label} {value} is outside {allowed.start}..{allowed.stop - 1}")
        return value

    def _limits(self, section: IniSection, data_type: DataType) -> tuple[int | None, int | None]:
        type_range = _type_range(data_type)
        low = self._integer(section, "Min", type_range) if "Min" in section else None
        high = self._integer(section, "Max", type_range) if "Max" in section else None
        if low is not None and high is not None and low > high:
            raise self.error(section, "Max", f"Max {high} is below Min {low}")
        return low, high

    def _indices(self, section: IniSection) -> range | None:
        text = section.get("Index")
        if text is None:
            return None
        match = _RANGE.match(text)
        if match is None:
            raise self.error(section, "Index", f"Index {text!r} must be FIRST..LAST")
        first, last = int(match["first"]), int(match["last"])
        if first > last or last not in INDEX_RANGE:
            raise self.error(section, "Index", f"Index {first}..{last} must be ascending within 0..255")
        return range(first, last + 1)

    def _defaults(
        self, section: IniSection, data_type: DataType, low: int | None, high: int | None, indices: range | None
    ) -> tuple[int, ...]:
        text = section.get("Default")
        if text is None:
            return ()
        values = tuple(self._integer(section, "Default", text=item) for item in text.split(","))
        count = len(indices) if indices is not None else 1
        if len(values) not in (1, count):
            raise self.error(section, "Default", f"Default gives {len(values)} values for {count} indices")
        allowed = range(_bound(low, data_type, 0), _bound(high, data_type, 1) + 1)
        for value in values:
            if value not in allowed:
                raise self.error(section, "Default", f"Default {value} is outside {allowed.start}..{allowed.stop - 1}")
        return values

    def _scale(self, section: IniSection) -> float:
        text = section.get("Scale")
        if text is None:
            return 1.0
        try:
            value = _number(text)
        except (ValueError, ZeroDivisionError):
            raise self.error(section, "Scale", f"Scale {text!r} is not a number (or a fraction a/b)") from None
        if value == 0 or not math.isfinite(value):
            raise self.error(section, "Scale", "Scale must be a finite number other than 0")
        return value

    def _enum(self, section: IniSection, data_type: DataType) -> dict[int, str]:
        allowed = _type_range(data_type)
        names: dict[int, str] = {}
        for entry in section:
            match = _ENUM.match(entry.key)
            if match is not None:
                value = self._integer(section, entry.key, allowed, match["value"], "Enum value")
                names[value] = entry.value
        return names

    def _bits(self, section: IniSection, data_type: DataType) -> tuple[BitField, ...]:
        width = data_type.fixed_size * 8
        fields: list[BitField] = []
        for entry in section:
            span = _bit_span(entry.key)
            if span is None:
                continue
            first, last = span
            if not first <= last < width:
                raise self.error(section, entry.key, f"bits {first}..{last} do not fit {width} bits")
            taken = [other.name for other in fields if other.first <= last and first <= other.last]
            if taken:
                raise self.error(section, entry.key, f"bits {first}..{last} overlap {taken[0]!r}")
            fields.append(BitField(first, last, entry.value))
        return tuple(sorted(fields, key=lambda bit_field: bit_field.first))


def _bit_span(key: str) -> tuple[int, int] | None:
    """`Bit.<n>` -> (n, n), `Bits.<a>-<b>` -> (a, b), other keys -> None."""
    single = _BIT.match(key)
    if single is not None:
        return int(single["bit"]), int(single["bit"])
    multiple = _BITS.match(key)
    return None if multiple is None else (int(multiple["first"]), int(multiple["last"]))


def _type_range(data_type: DataType) -> range:
    return range(int(data_type.min_value), int(data_type.max_value) + 1)  # type: ignore[arg-type]


def _bound(limit: int | None, data_type: DataType, end: int) -> int:
    """A limit, or the data type's minimum (end 0) / maximum (end 1)."""
    if limit is not None:
        return limit
    return int(data_type.min_value if end == 0 else data_type.max_value)  # type: ignore[arg-type]


def _number(text: str) -> float:
    """A decimal number or a fraction `a/b` (scales such as 100/32767 are exact as the manual states them)."""
    numerator, slash, denominator = text.partition("/")
    if slash:
        return float(numerator) / float(denominator)
    return float(text)
