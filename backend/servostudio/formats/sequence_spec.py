"""What SEQUENCE.TXT may say: sequence types, keywords, aliases, and the 0x3611 sub-index behind each keyword.

Everything here comes from the XtrapulsPac manual's sequence-mode chapter (seed 000, L9660–11281): the keyword
tables per sequence type, the 0x3611 sub-index definitions (data type, value range, default) and the keyword
list after the file syntax rules. Where the manual is silent or contradicts itself the project's
``decisions.md`` §3 settles it, and the remaining choices are documented in docs/file-formats.md:

- ``Accel``/``AccelTime`` and ``Decel``/``DecelTime`` are one keyword in every type; POS keeps them in
  acceleration units (subs 17/18), every other type in milliseconds (sub 19, and sub 20 for the ``Decel`` the
  HOME and TORQUE keyword lists name without a sub). GEAR has no deceleration keyword.
- ``Method`` accepts only the homing methods the drive implements (as 0x6098).
- Drive defaults the manual leaves blank: ``SeqNext``/``SeqLink`` = −1 (no sequence), everything else 0.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from enum import IntEnum
from types import MappingProxyType

#: Object that selects the sequence number accessed through 0x3611 (I16, manual L10680).
SEQUENCE_NUMBER_INDEX = 0x3610
#: Object whose subs 1..26 hold the parameters of the selected sequence (manual L10694).
SEQUENCE_PARAMETERS_INDEX = 0x3611
#: Sequence numbers the file syntax allows (SeqNb 0..127); a drive may support fewer (0x3612).
MAX_SEQUENCES = 128
#: Value of 0x3611,1 for an empty slot ("Not defined").
TYPE_NOT_DEFINED = 0
#: Value of 0x3611,1 for a cam sequence: the drive knows it, the file syntax has no constant for it.
TYPE_CAM = 6


class SequenceType(IntEnum):
    """The sequence types SEQUENCE.TXT can name, with their 0x3611,1 value."""

    POS = 1
    HOME = 2
    SPEED = 3
    TORQUE = 4
    GEAR = 5


@dataclass(frozen=True)
class ValueRange:
    """A set of allowed integers, as one or more closed intervals (homing methods need several)."""

    intervals: tuple[tuple[int, int], ...]

    def __contains__(self, value: object) -> bool:
        return isinstance(value, int) and any(low <= value <= high for low, high in self.intervals)

    def __str__(self) -> str:
        return ", ".join(f"{low}..{high}" for low, high in self.intervals)


def span(low: int, high: int) -> ValueRange:
    return ValueRange(((low, high),))


I16 = span(-0x8000, 0x7FFF)
U16 = span(0, 0xFFFF)
I32 = span(-0x8000_0000, 0x7FFF_FFFF)
U32 = span(0, 0xFFFF_FFFF)


@dataclass(frozen=True)
class SubIndex:
    """One sub of 0x3611 as the manual defines it (name, data type, value range, default)."""

    sub: int
    name: str
    data_type: str
    allowed: ValueRange
    default: int = 0
    unit: str = ""


SUBS: Mapping[int, SubIndex] = MappingProxyType(
    {
        entry.sub: entry
        for entry in (
            SubIndex(1, "Sequence Type", "Integer16", span(0, 6)),
            SubIndex(2, "Next sequence", "Integer16", span(-1, 127), default=-1),
            SubIndex(3, "Sequence Counter", "Unsigned16", U16),
            SubIndex(4, "Sequence Link", "Integer16", span(-1, 127), default=-1),
            SubIndex(5, "Output Trigger", "Unsigned16", U16),
            SubIndex(6, "Output Bits = 0", "Unsigned16", U16),
            SubIndex(7, "Output Bits = 1", "Unsigned16", U16),
            SubIndex(8, "Output Bits Toggle", "Unsigned16", U16),
            SubIndex(9, "Start Condition Bits = 0", "Unsigned16", U16),
            SubIndex(10, "Start Condition Bits = 1", "Unsigned16", U16),
            SubIndex(11, "End Condition Bits = 0", "Unsigned16", U16),
            SubIndex(12, "End Condition Bits = 1", "Unsigned16", U16),
            SubIndex(13, "Position", "Integer32", I32, unit="position unit"),
            SubIndex(14, "Position 2", "Integer32", I32, unit="position unit"),
            SubIndex(15, "Speed", "Integer32", I32, unit="speed unit"),
            SubIndex(16, "Speed 2 / Position 3", "Integer32", I32, unit="speed or position unit"),
            SubIndex(17, "Acceleration", "Unsigned32", U32, unit="acceleration unit"),
            SubIndex(18, "Deceleration", "Unsigned32", U32, unit="acceleration unit"),
            SubIndex(19, "Acceleration Time", "Unsigned16", span(1, 0xFFFF), unit="ms"),
            SubIndex(20, "Deceleration Time", "Unsigned16", span(0, 0xFFFF), unit="ms"),
            SubIndex(21, "Configuration", "Unsigned16", U16),
            SubIndex(22, "Configuration 2", "Integer16", I16),
            SubIndex(23, "Temporization", "Unsigned16", span(0, 16000), unit="ms"),
            SubIndex(24, "Running Time", "Unsigned16", U16, unit="ms, 65535 = infinite"),
            SubIndex(25, "Analog In", "Integer16", I16, unit="per mille of rated current"),
            SubIndex(26, "Analog In 2", "Integer16", I16),
        )
    }
)

#: Homing methods of the drive (0x6098, manual L8921–8974).
HOMING_METHODS = ValueRange(((-4, -1), (1, 14), (17, 30), (33, 35)))

TRIGGERS: Mapping[str, int] = MappingProxyType(
    {"BEGIN": 1 << 0, "CRUISE": 1 << 1, "DECEL": 1 << 2, "HOLD": 1 << 3, "END": 1 << 5}
)
POSITIONING_TYPES: Mapping[str, int] = MappingProxyType({"ABS": 0, "REL": 1})
SEQUENCE_TYPES: Mapping[str, int] = MappingProxyType({member.name: member.value for member in SequenceType})


def normalize(spelling: str) -> str:
    """Case and spaces do not matter in keywords (rule 1; the manual writes ``Home offset``, ``Start Cond``)."""
    return "".join(spelling.split()).lower()


@dataclass(frozen=True)
class Keyword:
    """A file keyword: its canonical spelling, accepted aliases, and the 0x3611 sub(s) it sets.

    A *pattern* keyword sets two subs, (bits = 0, bits = 1); a *constant* keyword takes a name from
    ``constants``; any other keyword takes a number. ``allowed`` narrows the sub's own range where the manual
    does (homing methods, ABS/REL).
    """

    name: str
    subs: tuple[int, ...]
    aliases: tuple[str, ...] = ()
    constants: Mapping[str, int] | None = None
    allowed: ValueRange | None = None
    spellings: frozenset[str] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "spellings", frozenset(normalize(s) for s in (self.name, *self.aliases)))

    @property
    def is_pattern(self) -> bool:
        return len(self.subs) == 2

    @property
    def sub(self) -> SubIndex:
        """The (first) sub this keyword sets."""
        return SUBS[self.subs[0]]

    @property
    def value_range(self) -> ValueRange:
        """Values a file may write for a number or constant keyword."""
        if self.constants is not None:
            return ValueRange(tuple((value, value) for value in sorted(self.constants.values())))
        return self.allowed or self.sub.allowed

    def constant_name(self, value: int) -> str | None:
        names = [name for name, number in (self.constants or {}).items() if number == value]
        return names[0] if names else None


SEQ_NB = "SeqNb"
DEFAULT_BLOCK = "Default"

SEQ_TYPE = Keyword("SeqType", (1,), constants=SEQUENCE_TYPES)
TEMPO = Keyword("Tempo", (23,))
SPEED = Keyword("Speed", (15,))
SPEED2 = Keyword("Speed2", (16,))
ACCEL_MS = Keyword("Accel", (19,), aliases=("AccelTime",))
DECEL_MS = Keyword("Decel", (20,), aliases=("DecelTime",))
RUN_TIME = Keyword("RunTime", (24,))
TORQUE_LIMIT = Keyword("Torque", (25,), aliases=("Current Limit",))

#: Keywords every sequence type has, in the order the writer puts them after the type-specific ones.
COMMON: tuple[Keyword, ...] = (
    TEMPO,
    Keyword("Trigger", (5,), constants=TRIGGERS),
    Keyword("Output", (6, 7)),
    Keyword("StartCond", (9, 10)),
    Keyword("EndCond", (11, 12)),
    Keyword("SeqNext", (2,), aliases=("NextSeq",)),
    Keyword("SeqCount", (3,)),
    Keyword("SeqLink", (4,)),
)

#: Type-specific keywords, in the order of the manual's keyword list (which the writer follows).
SPECIFIC: Mapping[SequenceType, tuple[Keyword, ...]] = MappingProxyType(
    {
        SequenceType.POS: (
            Keyword("PosType", (21,), constants=POSITIONING_TYPES),
            Keyword("Pos", (13,), aliases=("Position",)),
            SPEED,
            SPEED2,
            Keyword("Accel", (17,), aliases=("AccelTime",)),
            Keyword("Decel", (18,), aliases=("DecelTime",)),
        ),
        SequenceType.HOME: (
            Keyword("HomeOfs", (13,), aliases=("Home offset",)),
            SPEED,
            SPEED2,
            ACCEL_MS,
            DECEL_MS,
            Keyword("Method", (22,), allowed=HOMING_METHODS),
            TORQUE_LIMIT,
        ),
        SequenceType.SPEED: (
            SPEED,
            Keyword("AccelTime", (19,), aliases=("Accel",)),
            Keyword("DecelTime", (20,), aliases=("Decel",)),
            RUN_TIME,
        ),
        SequenceType.TORQUE: (SPEED, ACCEL_MS, DECEL_MS, RUN_TIME, TORQUE_LIMIT),
        SequenceType.GEAR: (
            Keyword("Config", (21,)),
            Keyword("Factor", (26,)),
            SPEED,
            ACCEL_MS,
            Keyword("MasterDtn", (13,)),
            Keyword("SlaveDtn", (14,)),
            Keyword("SyncDtn", (16,)),
        ),
    }
)

#: Subs a type gives a meaning to that no keyword can set; they must stay at their default (0).
UNREACHABLE_SUBS: Mapping[SequenceType, tuple[int, ...]] = MappingProxyType(
    {kind: ((8, 21) if kind is SequenceType.HOME else (8,)) for kind in SequenceType}
)


def keywords_for(kind: SequenceType) -> tuple[Keyword, ...]:
    """All parameters of a sequence of this type (SeqType excluded), in canonical write order."""
    return SPECIFIC[kind] + COMMON


_BY_SPELLING: Mapping[SequenceType, Mapping[str, Keyword]] = MappingProxyType(
    {
        kind: {spelling: keyword for keyword in keywords_for(kind) for spelling in keyword.spellings}
        for kind in SequenceType
    }
)


def find_keyword(kind: SequenceType, spelling: str) -> Keyword | None:
    """The keyword of this type a spelling (any alias, any case) stands for, or None."""
    return _BY_SPELLING[kind].get(normalize(spelling))


def find_any_type(spelling: str) -> Keyword | None:
    """The first keyword of any type (or SeqType) this spelling stands for; decides the value's syntax."""
    if normalize(spelling) in SEQ_TYPE.spellings:
        return SEQ_TYPE
    return next((found for kind in SequenceType if (found := find_keyword(kind, spelling)) is not None), None)
