"""Where a program goes: the start decision on entering a sequence and the next sequence after it ends.

decisions.md §3, from the *XtrapulsPac User Guide* §3.2.3.8 "Sequence chaining" (L10231–10339):
- a start condition that holds, or none, runs the sequence; one that does not hold skips it to SeqLink, or waits
  for the condition when SeqLink = −1;
- a sequence with SeqCount > 0 loads the counter when it first ends, and each end decrements it: while it is not 0
  the next sequence is SeqLink, at 0 SeqNext (the worked example's reading, not the prose of L10241);
- −1 as the next sequence ends the program.

The drive has one counter ("there must be only one SeqCount at a time", L10243): a sequence with its own SeqCount
that ends while another sequence's loop is counting takes the counter over, and the interrupted loop starts
counting afresh the next time it ends.
"""

from __future__ import annotations

import enum

from servostudio.sim.drive.sequencer.record import SequenceRecord

END_OF_PROGRAM = -1


class Entry(enum.Enum):
    RUN = "run"
    SKIP = "skip"
    WAIT = "wait"


def entry(record: SequenceRecord, conditional_input: int) -> Entry:
    """What entering `record` does with the conditional input 0x3601,3 as it is now."""
    if not record.start.defined or record.start.holds(conditional_input):
        return Entry.RUN
    return Entry.SKIP if record.link != END_OF_PROGRAM else Entry.WAIT


class LoopCounter:
    """The sequencer's one loop counter: which sequence loaded it and how many ends it still counts."""

    def __init__(self) -> None:
        self.owner: int | None = None
        self.remaining = 0

    def clear(self) -> None:
        """A new program starts with no loop counting."""
        self.owner = None
        self.remaining = 0

    def next_after(self, number: int, record: SequenceRecord) -> int:
        """The sequence that follows sequence `number` when it has run to its end."""
        if record.count == 0:
            return record.next
        if self.owner != number:
            self.owner, self.remaining = number, record.count
        self.remaining -= 1
        if self.remaining:
            return record.link
        self.clear()
        return record.next
