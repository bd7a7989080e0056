"""The parameter list of a PROFIBUS drive (PNU + IND) in the project's dictionary model.

A PROFIdrive-style drive has no object dictionary: it has parameter numbers (PNU 1..1999), each a word or a double
word, some of them arrays selected by the PKW index byte IND. The tool's editor, compare and projects work on an
`ObjectDictionary`, so a parameter list is one: index = PNU, subindex = IND (0 for a plain PNU), data type
UNSIGNED16/INTEGER16 for a word and UNSIGNED32/INTEGER32 for a double word (docs/profibus.md §2).

`Parameter` keeps what the dictionary model has no field for (IND range, procedure, "execute disabled", the save
class E/S/RAM, derived attributes), so the simulated drive and the PKW client read them from the same file.
"""

from __future__ import annotations

import enum
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

from servostudio.od.datatypes import DataType
from servostudio.od.model import Access, BitField, DictObject, ObjectDictionary, ObjectKind, SaveType, Variable

DOUBLE_TYPES = (DataType.UNSIGNED32, DataType.INTEGER32)
_PNU_ADDRESS = re.compile(
    r"^(?:pnu\s*)?(?P<pnu>\d{1,4})(?:\s*(?:\[(?P<bracket>\d{1,3})\]|,\s*(?P<comma>\d{1,3})))?$", re.I
)


class Persistence(enum.StrEnum):
    """Where a value survives power-off: E saved by PNU 729, S saved by PNU 781 (sequence write), RAM not saved."""

    E = "E"
    S = "S"
    RAM = "RAM"

    @property
    def save_type(self) -> SaveType:
        """The model's save type: E parameters are the drive's own save set (what DRIVEPAR is for the CANopen
        drives); sequences (S) and RAM values are outside it."""
        return SaveType.DRIVEPAR if self is Persistence.E else SaveType.NONE


@dataclass(frozen=True)
class Parameter:
    """One PNU as the manual lists it; `indices` is the IND range of an array PNU (None for a plain one)."""

    pnu: int
    name: str
    data_type: DataType
    access: Access
    persistence: Persistence = Persistence.RAM
    low: int | None = None
    high: int | None = None
    defaults: tuple[int, ...] = ()
    unit: str = ""
    scale: float = 1.0
    group: str = ""
    description: str = ""
    reference: str = ""
    derived: str = ""
    indices: range | None = None
    procedure: bool = False
    repeatable: bool = False
    """A procedure whose second run leaves the drive as one run does (a copy, a save): sent again when its station
    comes back into data exchange, as a read or a value write is (`drive/profibus/engine.py`)."""
    disabled_only: bool = False
    enum: Mapping[int, str] = field(default_factory=dict)
    bits: tuple[BitField, ...] = ()

    def __hash__(self) -> int:
        """Hash by PNU: the `enum` mapping makes the generated field-wise hash impossible."""
        return hash(self.pnu)

    @property
    def is_double(self) -> bool:
        """A double word travels in PWE bytes 5..8 (AK 3), a word in bytes 7..8 (AK 2)."""
        return self.data_type in DOUBLE_TYPES

    @property
    def index_range(self) -> range:
        return self.indices if self.indices is not None else range(1)

    def default_at(self, index: int) -> int | None:
        """The default of IND `index`: one value for all, or one per IND."""
        if not self.defaults:
            return None
        if len(self.defaults) == 1:
            return self.defaults[0]
        return self.defaults[self.index_range.index(index)]


class PnuVariable(Variable):
    """A dictionary entry addressed by PNU and IND, labelled the way the manual writes it."""

    @property
    def label(self) -> str:
        """ "PNU 700 Number of motor pole pairs", "PNU 795[5] Sequence control modification"."""
        address = f"PNU {self.index}" if self.parent_name == self.name else f"PNU {self.index}[{self.subindex}]"
        return f"{address} {self.parent_name}"


CONTROL_WORD = 0x800
STATUS_WORD = 0x801
"""The PZD1 words as dictionary entries, at addresses no PNU can have (the PKW PNU field has 11 bits: 0..2047), so
a `Drive` reads the status word and writes the control word like any object and the motion guard judges the control
word where it judges every write (docs/profibus.md §12); the PKW engine carries them through PZD, not PKW."""
POSITION_SET_POINT = 0x802
"""PZD5-6 of the PPO write: the position set point of the default command mapping (PNU 829 IND 2 = 0x22FF), which
replaces PNU 767 every cycle (L488-491, L2486), so a move's target must travel here, not through PKW."""


class PzdVariable(Variable):
    """A process-data word of the PPO (PZD1 control or status word), not a parameter."""

    @property
    def label(self) -> str:
        return self.name


class ParameterDictionary(ObjectDictionary):
    """An `ObjectDictionary` of PNUs that also keeps the `Parameter` records and the DP ident number, and the PZD1
    control and status words (`CONTROL_WORD`, `STATUS_WORD`)."""

    def __init__(self, device: str, product_name: str, ident_number: int, source: Path, parameters: list[Parameter]):
        self.ident_number = ident_number
        self.parameters = {parameter.pnu: parameter for parameter in sorted(parameters, key=lambda p: p.pnu)}
        objects = [_dictionary_object(parameter) for parameter in self.parameters.values()]
        super().__init__(device, product_name, 0, ident_number, 0, source, [*objects, *_process_data()])

    def find(self, name: str) -> Variable:
        """Look an entry up by PNU ("PNU700", "700", "PNU795[5]", "795,5") or by name (see ObjectDictionary)."""
        match = _PNU_ADDRESS.match(name.strip())
        if match is None:
            return super().find(name)
        index = int(match["bracket"] or match["comma"] or 0)
        variable = self.get(int(match["pnu"]), index)
        if variable is None:
            raise KeyError(f"{self.device}: no parameter {name!r}")
        return variable


def _process_data() -> list[DictObject]:
    """PZD1 of the PPO write (STW) and of the PPO read (ZSW): words, not saved, outside every backup."""
    words = (
        (CONTROL_WORD, "PZD1 control word STW", Access.RW, "the enabling commands and the positioner's (L427-478)"),
        (STATUS_WORD, "PZD1 status word ZSW", Access.RO, "the enabling stage and the positioner's state (L494-535)"),
    )
    set_point = (POSITION_SET_POINT, "PZD5-6 position set point", Access.RW, "replaces PNU 767 (L488-491, L2486)")
    return [
        DictObject(index, name, ObjectKind.VAR, PROCESS_DATA, {0: _pzd_variable(index, name, access, text, kind)})
        for (index, name, access, text), kind in [
            *((word, DataType.UNSIGNED16) for word in words),
            (set_point, DataType.INTEGER32),
        ]
    ]


PROCESS_DATA = "Process data (PZD)"


def _pzd_variable(index: int, name: str, access: Access, description: str, data_type: DataType) -> PzdVariable:
    return PzdVariable(index, 0, name, data_type, access, group=PROCESS_DATA, description=description, parent_name=name)


def _dictionary_object(parameter: Parameter) -> DictObject:
    kind = ObjectKind.VAR if parameter.indices is None else ObjectKind.ARRAY
    subs: dict[int, Variable] = {index: _variable(parameter, index) for index in parameter.index_range}
    return DictObject(parameter.pnu, parameter.name, kind, parameter.group, subs)


def _variable(parameter: Parameter, index: int) -> PnuVariable:
    name = parameter.name if parameter.indices is None else f"{parameter.name}[{index}]"
    return PnuVariable(
        index=parameter.pnu,
        subindex=index,
        name=name,
        data_type=parameter.data_type,
        access=parameter.access,
        low=parameter.low,
        high=parameter.high,
        default=parameter.default_at(index),
        unit=parameter.unit,
        scale=parameter.scale,
        save_type=parameter.persistence.save_type,
        group=parameter.group,
        description=parameter.description,
        enum=parameter.enum,
        bits=parameter.bits,
        reference=parameter.reference,
        parent_name=parameter.name,
    )
