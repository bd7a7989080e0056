"""The phases of a sequence: the bits of 0x3605 and of the output trigger 0x3611,5 (manual L10585–10598).

BEGIN the sequence begins; CRUISE the profile speed is reached; DECEL the deceleration begins; HOLD the reference
arrives at its target (a TORQUE sequence: the current reaches its limit); INPOS the position is inside the window
0x6067; END the sequence is over, after its Tempo. A motion reports the phases it reached in one control period as
these bits, so one period can pass several. 0x3605 holds the phases the running sequence has reached so far, so
none is lost when two fall into one period (a HOLD inside the position window is also INPOS at once).
"""

from __future__ import annotations

from collections.abc import Iterator

NONE = 0
BEGIN = 1 << 0
CRUISE = 1 << 1
DECEL = 1 << 2
HOLD = 1 << 3
INPOS = 1 << 4
END = 1 << 5

_IN_ORDER = (BEGIN, CRUISE, DECEL, HOLD, INPOS, END)


def in_order(phases: int) -> Iterator[int]:
    """The single phase bits of `phases`, in the order a sequence passes them."""
    return (phase for phase in _IN_ORDER if phases & phase)
