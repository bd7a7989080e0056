"""One sequence as the sequencer runs it: the 26 subs of its 0x3611 record, by meaning.

The sequencer reads a record once, when the sequence is entered, so a write to the sequence memory (0x3611,
`lseq`, `mseq`) never changes a sequence half-way through its run.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

INFINITE_RUN_TIME = 0xFFFF
"""RunTime 65535: the running (SPEED) or holding (TORQUE) phase lasts until an end condition or a stop."""
RELATIVE = 1
"""POS configuration (sub 21) bit 0: the position is relative to where the previous sequence left the axis."""


@dataclass(frozen=True)
class Condition:
    """A start or end condition on the conditional input 0x3601,3: bits that must be 0, bits that must be 1."""

    zeros: int
    ones: int

    @property
    def defined(self) -> bool:
        """A condition with no bit in either mask is "not defined" (the sequence starts, or never ends early)."""
        return bool(self.zeros | self.ones)

    def holds(self, bits: int) -> bool:
        return not bits & self.zeros and bits & self.ones == self.ones


@dataclass(frozen=True)
class SequenceRecord:
    """The subs of 0x3611 under the names the manual gives them (docs/file-formats.md, keyword table)."""

    type: int
    next: int
    count: int
    link: int
    trigger: int
    output_reset: int
    output_set: int
    output_toggle: int
    start: Condition
    end: Condition
    position: int
    position2: int
    speed: int
    speed2: int
    acceleration: int
    deceleration: int
    acceleration_time: int
    deceleration_time: int
    configuration: int
    configuration2: int
    tempo: int
    run_time: int
    analog: int
    analog2: int

    @classmethod
    def of(cls, subs: Mapping[int, int]) -> SequenceRecord:
        """The record of `SequenceMemory.record(number)` (every sub present, defaults for an empty slot)."""
        return cls(
            type=subs[1],
            next=subs[2],
            count=subs[3],
            link=subs[4],
            trigger=subs[5],
            output_reset=subs[6],
            output_set=subs[7],
            output_toggle=subs[8],
            start=Condition(subs[9], subs[10]),
            end=Condition(subs[11], subs[12]),
            position=subs[13],
            position2=subs[14],
            speed=subs[15],
            speed2=subs[16],
            acceleration=subs[17],
            deceleration=subs[18],
            acceleration_time=subs[19],
            deceleration_time=subs[20],
            configuration=subs[21],
            configuration2=subs[22],
            tempo=subs[23],
            run_time=subs[24],
            analog=subs[25],
            analog2=subs[26],
        )

    @property
    def infinite(self) -> bool:
        return self.run_time == INFINITE_RUN_TIME
