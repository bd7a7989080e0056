"""In-memory object dictionary: what a drive holds, as loaded from an EDS and its companion `.props` file.

Everything above the `od` layer reads object metadata (type, access, limits, unit, save type, enumerations, bit
fields) from these classes, so that device differences stay in data files rather than in code.
"""

from __future__ import annotations

import enum
import re
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path

from servostudio.errors import InvalidInput
from servostudio.od.datatypes import DataType


class DictionaryError(InvalidInput):
    """A dictionary file is malformed; names the file, the line, the section and the reason."""

    def __init__(self, file: Path | str, line: int, section: str, reason: str) -> None:
        self.file = str(file)
        self.line = line
        self.section = section
        self.reason = reason
        super().__init__(f"{self.file}:{line}: [{section}] {reason}")


class OutOfRange(InvalidInput):
    """A value lies outside the limits of the object it is meant for."""


class WrongType(InvalidInput, TypeError):
    """A value has a Python type the object's data type cannot hold."""


class Access(enum.StrEnum):
    """CiA 306 AccessType; rwr/rww are read-write objects preferably mapped into TPDOs/RPDOs."""

    RO = "ro"
    WO = "wo"
    RW = "rw"
    RWR = "rwr"
    RWW = "rww"
    CONST = "const"

    @property
    def readable(self) -> bool:
        return self is not Access.WO

    @property
    def writable(self) -> bool:
        return self in (Access.WO, Access.RW, Access.RWR, Access.RWW)


class SaveType(enum.StrEnum):
    """Which drive file an object's value is saved in (XtrapulsPac: DRIVEPAR.TXT or USER_PAR.TXT)."""

    DRIVEPAR = "DRIVEPAR"
    USER_PAR = "USER_PAR"
    NONE = "NONE"


class ObjectKind(enum.StrEnum):
    """CiA 306 ObjectType of a dictionary entry (DOMAIN objects are VARs whose data type is DOMAIN)."""

    VAR = "VAR"
    ARRAY = "ARRAY"
    RECORD = "RECORD"


@dataclass(frozen=True)
class BitField:
    """Bits `first`..`last` (inclusive) of an integer value; a single bit has first == last."""

    first: int
    last: int
    name: str

    @property
    def mask(self) -> int:
        return ((1 << (self.last - self.first + 1)) - 1) << self.first

    def extract(self, value: int) -> int:
        return (value & self.mask) >> self.first


Value = int | float | str | bytes


@dataclass(frozen=True)
class Variable:
    """One (index, subindex) entry with everything the tool needs to read, show, check and write it.

    `default` is the DefaultValue with any `$NODEID` term left out (so "$NODEID+0x180" gives 0x180);
    `default_for(node_id)` adds the node ID back. `default_expr` keeps the text as written in the EDS.
    A DCF's ParameterValue (the value commissioning configured) is kept the same way in `parameter_value`,
    `parameter_expr` and `parameter_value_for(node_id)`.
    """

    index: int
    subindex: int
    name: str
    data_type: DataType
    access: Access
    pdo_mappable: bool = False
    low: int | float | None = None
    high: int | float | None = None
    default: Value | None = None
    default_expr: str | None = None
    unit: str = ""
    scale: float = 1.0
    offset: float = 0.0
    save_type: SaveType = SaveType.NONE
    group: str = ""
    description: str = ""
    enum: Mapping[int, str] = field(default_factory=dict)
    bits: tuple[BitField, ...] = ()
    is_pointer: bool = False
    reference: str = ""
    parent_name: str = ""
    default_uses_node_id: bool = False
    parameter_value: Value | None = None
    parameter_expr: str | None = None
    parameter_uses_node_id: bool = False

    def __hash__(self) -> int:
        """Hash by address: the `enum` mapping makes the generated field-wise hash impossible."""
        return hash((self.index, self.subindex, self.name))

    @property
    def key(self) -> tuple[int, int]:
        return (self.index, self.subindex)

    @property
    def label(self) -> str:
        """Human-readable address, e.g. "0x60F9,2 Speed loop gains.KPv"."""
        if self.parent_name and self.parent_name != self.name:
            return f"0x{self.index:04X},{self.subindex} {self.parent_name}.{self.name}"
        return f"0x{self.index:04X},{self.subindex} {self.name}"

    @property
    def minimum(self) -> int | float | None:
        """Effective lower bound: the EDS LowLimit, else the data type's own minimum."""
        return self.low if self.low is not None else self.data_type.min_value

    @property
    def maximum(self) -> int | float | None:
        """Effective upper bound: the EDS HighLimit, else the data type's own maximum."""
        return self.high if self.high is not None else self.data_type.max_value

    def default_for(self, node_id: int) -> Value | None:
        """DefaultValue with `$NODEID` replaced by `node_id`."""
        return _for_node(self.default, self.default_uses_node_id, node_id)

    def parameter_value_for(self, node_id: int) -> Value | None:
        """A DCF's ParameterValue with `$NODEID` replaced by `node_id` (None: the file configures nothing here)."""
        return _for_node(self.parameter_value, self.parameter_uses_node_id, node_id)

    @property
    def default_node_offset(self) -> int | None:
        """What a `$NODEID` default adds to the node ID (0x180 for "$NODEID+0x180"); None for a fixed default."""
        return _node_offset(self.default, self.default_uses_node_id)

    @property
    def parameter_node_offset(self) -> int | None:
        """What a `$NODEID` ParameterValue adds to the node ID; None for a fixed or no ParameterValue."""
        return _node_offset(self.parameter_value, self.parameter_uses_node_id)

    def to_physical(self, raw: int | float) -> float:
        """physical = raw * scale + offset (the unit is `self.unit`)."""
        return raw * self.scale + self.offset

    def from_physical(self, value: float) -> int | float:
        """Inverse of `to_physical`, rounded to the nearest integer for integer types."""
        raw = (value - self.offset) / self.scale
        return round(raw) if self.data_type.is_integer else raw

    def check(self, value: Value) -> None:
        """Raise WrongType / OutOfRange when `value` cannot be written to this object."""
        data_type = self.data_type
        if data_type.is_integer or data_type.is_time:
            if isinstance(value, bool) or not isinstance(value, int):
                raise WrongType(f"{self.label}: {data_type.name} needs an integer, got {value!r}")
        elif data_type.is_float:
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise WrongType(f"{self.label}: {data_type.name} needs a number, got {value!r}")
        elif data_type.is_text:
            if not isinstance(value, str):
                raise WrongType(f"{self.label}: {data_type.name} needs text, got {value!r}")
            return
        else:
            if not isinstance(value, (bytes, bytearray)):
                raise WrongType(f"{self.label}: {data_type.name} needs bytes, got {value!r}")
            return
        low, high = self.minimum, self.maximum
        if (low is not None and value < low) or (high is not None and value > high):
            raise OutOfRange(f"{self.label}: {value} is outside {low}..{high}")


def _for_node(value: Value | None, uses_node_id: bool, node_id: int) -> Value | None:
    """An EDS value for one node: the `$NODEID` term is the only part of a value that depends on the node."""
    return value + node_id if uses_node_id and isinstance(value, int) else value


def _node_offset(value: Value | None, uses_node_id: bool) -> int | None:
    return value if uses_node_id and isinstance(value, int) else None


@dataclass
class DictObject:
    """One index: a VAR (single sub 0), an ARRAY or a RECORD with its sub-entries."""

    index: int
    name: str
    kind: ObjectKind
    group: str
    subs: dict[int, Variable]


_ADDRESS = re.compile(
    r"^(?:0x)?(?P<index>[0-9a-f]{1,4})(?:\s*(?P<sep>,|:|sub)\s*(?P<sub>(?:0x)?[0-9a-f]+))?$", re.IGNORECASE
)


def _parse_address(text: str) -> tuple[int, int] | None:
    """ "0x6041" -> (0x6041, 0); "60F9,2" and "60F9:2" take a decimal (or 0x-prefixed) sub; "60F9sub2" a hex one."""
    match = _ADDRESS.match(text)
    if not match:
        return None
    index = int(match["index"], 16)
    sub_text = match["sub"]
    if sub_text is None:
        return (index, 0)
    base = 16 if match["sep"].lower() == "sub" or sub_text.lower().startswith("0x") else 10
    try:
        return (index, int(sub_text, base))
    except ValueError:
        return None


class ObjectDictionary:
    """All objects of one device, indexed by (index, subindex)."""

    def __init__(
        self,
        device: str,
        product_name: str,
        vendor_id: int,
        product_code: int,
        revision: int,
        source: Path,
        objects: list[DictObject],
    ) -> None:
        self.device = device
        self.product_name = product_name
        self.vendor_id = vendor_id
        self.product_code = product_code
        self.revision = revision
        self.source = source
        self._objects = {obj.index: obj for obj in sorted(objects, key=lambda o: o.index)}
        self._variables = {
            (var.index, var.subindex): var for obj in self._objects.values() for var in obj.subs.values()
        }
        self._sorted_variables = sorted(self._variables.values(), key=lambda v: v.key)

    def __repr__(self) -> str:
        return f"ObjectDictionary({self.device!r}, {len(self._objects)} objects, source={str(self.source)!r})"

    def __getitem__(self, key: tuple[int, int]) -> Variable:
        return self._variables[key]

    def __contains__(self, key: object) -> bool:
        """`(index, sub) in od` tests an entry, `index in od` tests an object."""
        if isinstance(key, tuple):
            return key in self._variables
        return key in self._objects

    def __len__(self) -> int:
        return len(self._variables)

    def get(self, index: int, subindex: int = 0) -> Variable | None:
        return self._variables.get((index, subindex))

    def object(self, index: int) -> DictObject:
        return self._objects[index]

    def objects(self) -> list[DictObject]:
        return list(self._objects.values())

    def groups(self) -> list[str]:
        """UI group names in the order of their first object (by index); objects without a group are left out."""
        return list(dict.fromkeys(obj.group for obj in self._objects.values() if obj.group))

    def variables(self) -> Iterator[Variable]:
        """Every entry, by index and subindex."""
        return iter(self._sorted_variables)

    def find(self, name: str) -> Variable:
        """Look an entry up by address ("0x6041", "60F9,2", "0x60F9sub2") or by name.

        Names match a VAR's name, a sub-entry's "Parent.Sub" name, or a sub-entry's own name when that is unique
        in the dictionary (case-insensitive). Raises KeyError when nothing or more than one entry matches.
        """
        text = name.strip()
        key = _parse_address(text)
        if key in self._variables:
            return self._variables[key]
        wanted = text.casefold()
        matches = [
            var
            for var in self._variables.values()
            if wanted in (var.name.casefold(), f"{var.parent_name}.{var.name}".casefold())
        ]
        exact_var = [var for var in matches if var.parent_name == var.name]
        if len(exact_var) == 1:
            return exact_var[0]
        if len(matches) == 1:
            return matches[0]
        if not matches:
            raise KeyError(f"{self.device}: no object named {name!r}")
        raise KeyError(f"{self.device}: {name!r} is ambiguous: " + ", ".join(v.label for v in matches[:5]))
