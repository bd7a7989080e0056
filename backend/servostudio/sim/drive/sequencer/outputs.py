"""The sequence outputs 0x3602 (manual L10440–10560): the programmable logic outputs the sequences switch and the
dedicated outputs POS, SEQ, SPEED and READY.

- Programmable (0x3602,1): at each phase in its Trigger (0x3611,5) a sequence resets the bits of sub 6, sets those
  of sub 7, then toggles those of sub 8. A bit marked in 0x3604,1 is a pulse output: when it comes on it goes off
  again after 0x3604,2 ms (0: it stays, like a level output). A Trigger of 0 switches nothing. The object is rw: a
  bus write sets the outputs directly.
- Dedicated (0x3602,3): POS on at INPOS (the motor reached its position) until the next sequence begins; SEQ while
  a program runs, and for at least 0x3603 ms after it rose (so a short sequence is still seen); SPEED from CRUISE
  to DECEL (the speed set-point is reached during a move); READY while the drive has no error.
- The objects show each logical output through its polarity (0x3602,2 / 0x3602,4, 1 = negative); status word
  bits 12 and 13 in sequence mode are the logical POS and SEQ.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from servostudio.od.model import Value
from servostudio.sim.drive.sequencer.phases import BEGIN, CRUISE, DECEL, END, INPOS
from servostudio.sim.drive.sequencer.record import SequenceRecord

if TYPE_CHECKING:
    from servostudio.sim.drive.behaviour import DriveBehaviour

PROGRAMMABLE, PROGRAMMABLE_POLARITY, DEDICATED, DEDICATED_POLARITY = ((0x3602, sub) for sub in (1, 2, 3, 4))
MINIMUM_SEQ_PULSE = (0x3603, 0)
PULSE_OUTPUTS, PULSE_DURATION = (0x3604, 1), (0x3604, 2)
POS, SEQ, SPEED, READY = 1 << 0, 1 << 1, 1 << 2, 1 << 3

_DEDICATED_ON = {CRUISE: SPEED, INPOS: POS}
_DEDICATED_OFF = {BEGIN: POS | SPEED, DECEL: SPEED, END: SPEED}


class SequenceOutputs:
    def __init__(self, drive: DriveBehaviour) -> None:
        self.drive = drive
        self.store = store = drive.store
        self.programmable = 0
        self.dedicated = 0
        self._pulses: dict[int, float] = {}  # bits that came on together → when they go off
        self._seq_rise = -math.inf
        self._seq_fall = math.inf
        self._next_fall = math.inf
        store.on_write(*PROGRAMMABLE, self._programmable_written)
        store.on_write(*PROGRAMMABLE_POLARITY, lambda index, sub, value: self._publish_programmable(int(value)))
        store.on_write(*DEDICATED_POLARITY, lambda index, sub, value: self._publish_dedicated(int(value)))

    def reset(self) -> None:
        """Power-on (warm reset): every output off."""
        self.programmable = self.dedicated = 0
        self._pulses.clear()
        self._seq_fall = self._next_fall = math.inf
        self._publish_programmable()
        self._publish_dedicated()

    # -- what the sequencer tells ------------------------------------------------------------------------------

    def phase_reached(self, phase: int, record: SequenceRecord) -> None:
        if phase & record.trigger:
            self.switch(record)
        self._set_dedicated(self.dedicated & ~_DEDICATED_OFF.get(phase, 0) | _DEDICATED_ON.get(phase, 0))

    def switch(self, record: SequenceRecord) -> None:
        """The sequence's Output: reset, set, then toggle."""
        before = self.programmable
        after = (before & ~record.output_reset | record.output_set) ^ record.output_toggle
        self.programmable = after & 0xFFFF
        self._start_pulses(self.programmable & ~before)
        self._publish_programmable()

    def program_started(self) -> None:
        self._seq_rise = self.drive.time
        self._seq_fall = math.inf
        self._set_dedicated(self.dedicated | SEQ)

    def program_ended(self) -> None:
        """SEQ falls now, or when it has lasted the minimum sequence pulse 0x3603."""
        self._seq_fall = self._seq_rise + int(self.store.get(*MINIMUM_SEQ_PULSE)) / 1000.0
        self._next_fall = min(self._next_fall, self._seq_fall)
        self.tick()

    def tick(self) -> None:
        """Every control period in sequence mode (every status update outside Operation Enabled): the pulses and
        the SEQ stretch that are due, and READY."""
        if self.drive.time >= self._next_fall - self.drive.dt / 2:
            self._fall(self.drive.time + self.drive.dt / 2)
        ready = READY if not self.drive.active_errors else 0
        if self.dedicated & READY != ready:
            self._set_dedicated(self.dedicated ^ READY)

    # -- timing ------------------------------------------------------------------------------------------------

    def _start_pulses(self, rising: int) -> None:
        pulses = rising & int(self.store.get(*PULSE_OUTPUTS))
        duration = int(self.store.get(*PULSE_DURATION))
        if pulses and duration:
            falls = self.drive.time + duration / 1000.0
            self._pulses[pulses] = falls
            self._next_fall = min(self._next_fall, falls)

    def _fall(self, now: float) -> None:
        due = [bits for bits, falls in self._pulses.items() if falls <= now]
        for bits in due:
            del self._pulses[bits]
            self.programmable &= ~bits
        if due:
            self._publish_programmable()
        if self._seq_fall <= now:
            self._seq_fall = math.inf
            self._set_dedicated(self.dedicated & ~SEQ)
        self._next_fall = min([self._seq_fall, *self._pulses.values()])

    # -- objects -----------------------------------------------------------------------------------------------

    def _programmable_written(self, index: int, sub: int, value: Value) -> None:
        """A bus write sets the output levels: the logical state is the level through the polarity."""
        self.programmable = int(value) ^ int(self.store.get(*PROGRAMMABLE_POLARITY))

    def _publish_programmable(self, polarity: int | None = None) -> None:
        if polarity is None:
            polarity = int(self.store.get(*PROGRAMMABLE_POLARITY))
        self.store.set(*PROGRAMMABLE, (self.programmable ^ polarity) & 0xFFFF)

    def _set_dedicated(self, dedicated: int) -> None:
        if dedicated != self.dedicated:
            self.dedicated = dedicated
            self._publish_dedicated()

    def _publish_dedicated(self, polarity: int | None = None) -> None:
        if polarity is None:
            polarity = int(self.store.get(*DEDICATED_POLARITY))
        self.store.set(*DEDICATED, (self.dedicated ^ polarity) & 0xFFFF)
