"""The 8-byte PKW message: PKE (AK, SPM, PNU), IND, PWE, big-endian (TTA-PRO Profibus Communication Profile,
Chapter 1 §3, L269-381).

| bytes | field |
|---|---|
| 1-2 | PKE: bits 15-12 AK (instruction or reply), bit 11 SPM (spontaneous message), bits 10-0 PNU |
| 3 | IND: sequence number for PNU 795-807/815, mapping slot for 828/829, else 0 |
| 4 | reserved, 0 |
| 5-8 | PWE: a word in bytes 7 (MSB) and 8 (LSB), a double word in bytes 5 (MSB) to 8 (LSB) |

So a word and a double word are both the 32-bit big-endian PWE, a word with its upper half zero; signed values
travel in two's complement of their own width.
"""

from __future__ import annotations

import enum
import struct
from dataclasses import dataclass

LENGTH = 8
_LAYOUT = struct.Struct(">HBxI")
PNU_MASK = 0x07FF
SPONTANEOUS = 0x0800
AK_SHIFT = 12


class Instruction(enum.IntEnum):
    """AK of a request (master → slave)."""

    NONE = 0
    READ = 1
    WRITE_WORD = 2
    WRITE_DOUBLE = 3


class Reply(enum.IntEnum):
    """AK of a reply (slave → master). The manual prints 1 for a word and for a double word value (L311-318);
    PROFIdrive uses 2 for a double word, which a client accepts too."""

    NONE = 0
    VALUE = 1
    VALUE_DOUBLE = 2
    REFUSED = 7
    INHIBITED = 8


@dataclass(frozen=True)
class PkwMessage:
    """One PKW module in either direction; `value` is PWE as an unsigned 32-bit number."""

    ak: int
    pnu: int
    index: int = 0
    value: int = 0
    spontaneous: bool = False

    def __post_init__(self) -> None:
        if not 0 <= self.ak <= 0xF or not 0 <= self.pnu <= PNU_MASK or not 0 <= self.index <= 0xFF:
            raise ValueError(f"PKW fields out of range: AK {self.ak}, PNU {self.pnu}, IND {self.index}")
        if not 0 <= self.value <= 0xFFFFFFFF:
            raise ValueError(f"PWE {self.value} is not an unsigned 32-bit value")

    @property
    def pke(self) -> int:
        return self.ak << AK_SHIFT | (SPONTANEOUS if self.spontaneous else 0) | self.pnu

    def encode(self) -> bytes:
        return _LAYOUT.pack(self.pke, self.index, self.value)

    @classmethod
    def decode(cls, data: bytes) -> PkwMessage:
        if len(data) != LENGTH:
            raise ValueError(f"a PKW module has {LENGTH} bytes, got {len(data)}")
        pke, index, value = _LAYOUT.unpack(data)
        return cls(pke >> AK_SHIFT, pke & PNU_MASK, index, value, bool(pke & SPONTANEOUS))


IDLE = PkwMessage(Instruction.NONE, 0)
"""AK 0: no parameter traffic (also the separator between two identical procedure requests)."""


def read_request(pnu: int, index: int = 0) -> PkwMessage:
    return PkwMessage(Instruction.READ, pnu, index)


def write_request(pnu: int, value: int, double: bool, index: int = 0) -> PkwMessage:
    """AK 2 for a word, AK 3 for a double word; `value` may be negative (two's complement of its width)."""
    ak = Instruction.WRITE_DOUBLE if double else Instruction.WRITE_WORD
    return PkwMessage(ak, pnu, index, to_pwe(value, double))


def to_pwe(value: int, double: bool) -> int:
    """A signed or unsigned value as the PWE field: word values in the low half."""
    bits = 32 if double else 16
    if not -(1 << (bits - 1)) <= value < 1 << bits:
        raise ValueError(f"{value} does not fit a {'double word' if double else 'word'}")
    return value & ((1 << bits) - 1)


def from_pwe(pwe: int, double: bool, signed: bool) -> int:
    """The value a PWE carries for a word or double word parameter (a word is read from bytes 7-8 only)."""
    bits = 32 if double else 16
    raw = pwe & ((1 << bits) - 1)
    if signed and raw >= 1 << (bits - 1):
        return raw - (1 << bits)
    return raw
