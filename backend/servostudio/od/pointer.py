"""The drive's "dataflow" pointer convention: a U32 holding `index << 16 | sub << 8 | low byte`.

XtrapulsPac link objects (0x3044, 0x3050, 0x30DA, …), PDO mapping entries and the oscilloscope channel sources all use
it; the low byte is a bit number (links to one bit) or a size in bits (PDO mapping, scope channels), 0 for "whole
object". Objects holding such a value have `Variable.is_pointer`.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Pointer:
    index: int
    subindex: int
    low: int = 0

    def __post_init__(self) -> None:
        if not (0 <= self.index <= 0xFFFF and 0 <= self.subindex <= 0xFF and 0 <= self.low <= 0xFF):
            raise ValueError(f"pointer fields out of range: {self}")

    @classmethod
    def decode(cls, value: int) -> Pointer:
        if not 0 <= value <= 0xFFFF_FFFF:
            raise ValueError(f"{value:#x} is not a 32-bit pointer")
        return cls(value >> 16, (value >> 8) & 0xFF, value & 0xFF)

    def encode(self) -> int:
        return self.index << 16 | self.subindex << 8 | self.low

    @property
    def key(self) -> tuple[int, int]:
        return (self.index, self.subindex)

    def __str__(self) -> str:
        return f"0x{self.index:04X},{self.subindex}/{self.low}"
