"""Sequences as values: a ``Sequence`` is one basic move, a ``SequenceTable`` maps sequence numbers to them.

The model holds exactly what SEQUENCE.TXT can express, so any table can be written to a file and read back
equal. It converts to and from the 0x3611 sub-index values the drive stores, which is how the tool reads and
writes sequence memory: select the number in 0x3610, then read or write 0x3611 subs 1..26.
"""

from __future__ import annotations

import re
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from enum import Enum
from types import MappingProxyType

from servostudio.formats.sequence_spec import (
    MAX_SEQUENCES,
    SEQUENCE_NUMBER_INDEX,
    SEQUENCE_PARAMETERS_INDEX,
    SUBS,
    TYPE_CAM,
    TYPE_NOT_DEFINED,
    UNREACHABLE_SUBS,
    Keyword,
    SequenceType,
    keywords_for,
)

PATTERN_WIDTH = 8
_PATTERN = re.compile(r'"([01.]{8})"')


@dataclass(frozen=True)
class BitPattern:
    """An 8-character pattern such as ``"..001000"``: leftmost character is bit 7 (MSB first).

    For ``Output``, ``zeros`` are the outputs reset and ``ones`` the outputs set (subs 6/7); for ``StartCond``
    and ``EndCond`` they are the condition bits that must be 0 and 1. ``.`` leaves a bit alone.
    """

    zeros: int = 0
    ones: int = 0

    def __post_init__(self) -> None:
        limit = 1 << PATTERN_WIDTH
        if not (0 <= self.zeros < limit and 0 <= self.ones < limit):
            raise ValueError(
                f"pattern bits must be within bits 0..{PATTERN_WIDTH - 1} "
                f"(zeros=0x{self.zeros:X}, ones=0x{self.ones:X})"
            )
        if self.zeros & self.ones:
            raise ValueError(f"pattern bits 0x{self.zeros & self.ones:X} cannot be both 0 and 1")

    @classmethod
    def parse(cls, text: str) -> BitPattern:
        """Parse the quoted file form; ValueError says what a pattern must look like."""
        match = _PATTERN.fullmatch(text.strip())
        if match is None:
            raise ValueError(
                f"a pattern is 8 characters of 1, 0 or . in double quotes, MSB first "
                f'(e.g. "..001000"), got {text.strip()!r}'
            )
        chars = match.group(1)
        bits = {position: chars[PATTERN_WIDTH - 1 - position] for position in range(PATTERN_WIDTH)}
        return cls(
            zeros=sum(1 << bit for bit, char in bits.items() if char == "0"),
            ones=sum(1 << bit for bit, char in bits.items() if char == "1"),
        )

    def __str__(self) -> str:
        chars = [
            "1" if self.ones >> bit & 1 else "0" if self.zeros >> bit & 1 else "."
            for bit in reversed(range(PATTERN_WIDTH))
        ]
        return '"' + "".join(chars) + '"'


Value = int | BitPattern


def default_value(keyword: Keyword) -> Value:
    """What a parameter the file does not declare holds (rule 9, before any ``Default`` block)."""
    return BitPattern() if keyword.is_pattern else keyword.sub.default


def value_problem(keyword: Keyword, value: Value) -> str | None:
    """Why ``value`` cannot be written for ``keyword`` in a file (range, constants), or None if it can."""
    if keyword.is_pattern:
        return None if isinstance(value, BitPattern) else f"needs a bit pattern, got {value!r}"
    if isinstance(value, BitPattern) or not isinstance(value, int):
        return f"needs a number, got {value!r}"
    if value in keyword.value_range:
        return None
    if keyword.constants is not None:
        return f"{value} has no constant; allowed: {', '.join(keyword.constants)}"
    sub = keyword.sub
    unit = f", {sub.unit}" if sub.unit else ""
    return (
        f"value {value} is out of range: allowed {keyword.value_range} "
        f"(0x{SEQUENCE_PARAMETERS_INDEX:04X},{sub.sub} {sub.name}: {sub.data_type}{unit})"
    )


@dataclass(frozen=True)
class Sequence:
    """One sequence: its type and the value of every parameter of that type (keyed by canonical keyword).

    Parameters left out take their default, so two sequences that behave alike compare equal. A value must be
    one a file can write, or the parameter's default (e.g. ``AccelTime`` 0, the drive's default, although a
    file may only write 1..65535).
    """

    type: SequenceType
    values: Mapping[str, Value]

    def __post_init__(self) -> None:
        kind = SequenceType(self.type)
        keywords = keywords_for(kind)
        unknown = set(self.values) - {keyword.name for keyword in keywords}
        if unknown:
            raise ValueError(f"not parameters of a {kind.name} sequence: {', '.join(sorted(unknown))}")
        complete = {keyword.name: self.values.get(keyword.name, default_value(keyword)) for keyword in keywords}
        for keyword in keywords:
            value = complete[keyword.name]
            problem = value_problem(keyword, value)
            if problem is not None and value != default_value(keyword):
                raise ValueError(f"{keyword.name}: {problem}")
        object.__setattr__(self, "type", kind)
        object.__setattr__(self, "values", MappingProxyType(complete))

    @classmethod
    def of(cls, kind: SequenceType, **values: Value) -> Sequence:
        """Build a sequence from keyword arguments named like the file's canonical keywords."""
        return cls(kind, values)

    def __getitem__(self, keyword: str) -> Value:
        return self.values[keyword]

    def __hash__(self) -> int:
        return hash((self.type, tuple(self.values.items())))

    def to_object_values(self) -> dict[int, int]:
        """All 26 subs of 0x3611: the type, this type's parameters, every other sub at its default.

        Writing every sub matters: a sequence slot may hold leftovers of an earlier sequence of another type.
        """
        record = {sub: entry.default for sub, entry in SUBS.items()}
        record[1] = int(self.type)
        for keyword in keywords_for(self.type):
            value = self.values[keyword.name]
            if isinstance(value, BitPattern):
                record[keyword.subs[0]], record[keyword.subs[1]] = value.zeros, value.ones
            else:
                record[keyword.subs[0]] = value
        return record

    @classmethod
    def from_object_values(cls, record: Mapping[int, int]) -> Sequence | None:
        """The sequence a 0x3611 record holds; None for an empty slot (type 0).

        Subs this type does not use are ignored. ValueError when a used sub holds something SEQUENCE.TXT
        cannot say (cam type, toggled outputs, INPOS or combined triggers, the homing return option, pattern
        bits above bit 7, values out of range), because such a sequence could not be saved to a file.
        """

        def sub_value(sub: int) -> int:
            return record.get(sub, SUBS[sub].default)

        type_value = sub_value(1)
        if type_value == TYPE_NOT_DEFINED:
            return None
        if type_value == TYPE_CAM:
            raise ValueError("sequence type 6 (CAM) has no SEQUENCE.TXT syntax")
        try:
            kind = SequenceType(type_value)
        except ValueError:
            raise ValueError(f"sequence type {type_value} is not one of 0..6") from None
        for sub in UNREACHABLE_SUBS[kind]:
            if sub_value(sub) != SUBS[sub].default:
                raise ValueError(
                    f"0x3611,{sub} ({SUBS[sub].name}) = {sub_value(sub)} in a {kind.name} sequence "
                    f"has no SEQUENCE.TXT keyword"
                )
        values: dict[str, Value] = {}
        for keyword in keywords_for(kind):
            if keyword.is_pattern:
                values[keyword.name] = _pattern_from(keyword, sub_value(keyword.subs[0]), sub_value(keyword.subs[1]))
            else:
                values[keyword.name] = sub_value(keyword.subs[0])
        return cls(kind, values)


def _pattern_from(keyword: Keyword, zeros: int, ones: int) -> BitPattern:
    try:
        return BitPattern(zeros, ones)
    except ValueError as error:
        raise ValueError(f"{keyword.name} (0x3611,{keyword.subs[0]}/{keyword.subs[1]}): {error}") from None


@dataclass(frozen=True)
class ObjectWrite:
    """One SDO download the tool performs to put a table into sequence memory."""

    index: int
    sub: int
    value: int


class LoadMode(Enum):
    """How the drive takes a SEQUENCE.TXT into sequence memory (0x1011 ``lseq`` / ``mseq``)."""

    LOAD = "load"
    MERGE = "merge"


@dataclass(frozen=True)
class SequenceTable:
    """Sequences by number (0..127), ascending; numbers not present are empty slots."""

    sequences: Mapping[int, Sequence]

    def __post_init__(self) -> None:
        for number, sequence in self.sequences.items():
            if not 0 <= number < MAX_SEQUENCES:
                raise ValueError(f"sequence number {number} out of range 0..{MAX_SEQUENCES - 1}")
            if not isinstance(sequence, Sequence):
                raise TypeError(f"sequence {number} is a {type(sequence).__name__}, not a Sequence")
        object.__setattr__(self, "sequences", MappingProxyType(dict(sorted(self.sequences.items()))))

    def __iter__(self) -> Iterator[int]:
        return iter(self.sequences)

    def __len__(self) -> int:
        return len(self.sequences)

    def __getitem__(self, number: int) -> Sequence:
        return self.sequences[number]

    def __hash__(self) -> int:
        return hash(tuple(self.sequences.items()))

    def apply_to(self, memory: SequenceTable, mode: LoadMode) -> SequenceTable:
        """The sequence memory after the drive takes this (file) table in ``mode``.

        LOAD: memory becomes exactly this table; every slot the file does not declare is cleared.
        MERGE: each declared sequence replaces the slot of the same number *as a whole* (its undeclared
        parameters take defaults, not the old values); undeclared slots keep what they held.
        """
        if mode is LoadMode.LOAD:
            return self
        return SequenceTable({**memory.sequences, **self.sequences})

    def to_object_writes(self, clear_below: int | None = None) -> list[ObjectWrite]:
        """The writes that put this table into sequence memory: per sequence, 0x3610 = number, then subs 1..26.

        With ``clear_below`` (the drive's 0x3612, for LOAD semantics) every other slot below it is cleared
        by writing 0x3611,1 = 0 ("not defined"); without it the other slots are left alone (MERGE).
        """
        if clear_below is not None and any(number >= clear_below for number in self.sequences):
            raise ValueError(f"the table has sequence numbers >= {clear_below}, the drive's maximum")
        writes: list[ObjectWrite] = []
        numbers = range(clear_below) if clear_below is not None else self.sequences
        for number in numbers:
            writes.append(ObjectWrite(SEQUENCE_NUMBER_INDEX, 0, number))
            sequence = self.sequences.get(number)
            record = sequence.to_object_values() if sequence else {1: TYPE_NOT_DEFINED}
            writes.extend(ObjectWrite(SEQUENCE_PARAMETERS_INDEX, sub, value) for sub, value in record.items())
        return writes

    @classmethod
    def from_object_values(cls, records: Mapping[int, Mapping[int, int]]) -> SequenceTable:
        """The table held by per-number 0x3611 records (as read after selecting each number in 0x3610)."""
        sequences: dict[int, Sequence] = {}
        for number, record in records.items():
            try:
                sequence = Sequence.from_object_values(record)
            except ValueError as error:
                raise ValueError(f"sequence {number}: {error}") from None
            if sequence is not None:
                sequences[number] = sequence
        return cls(sequences)
