"""The TTA-PRO's manual homing configurations (PNU 766), as the quick test's homing "methods".

The TTA-PRO has no CiA 402 method numbers: its manual homing (CW11 rising edge) is a composition of PNU 766's bits
(TTA-PRO Profibus Communication Profile, L1732-1761): bit 3 direction (1 = negative), bit 4 search the home
switch, bit 5 search the marker pulse, bit 6 move onto the home position once found (else stop there), bit 7 set
the position counter to the homing offset PNU 768 there. A "method" of this drive is that value of PNU 766, and
its description is the manual's reading of its bits; every composition is offered (28: the direction bit means
nothing without a signal to search).
"""

from __future__ import annotations

DIRECTION_NEGATIVE, WITH_SWITCH, WITH_MARKER, MOVE_TO_HOME, RESET_COUNTER = 1 << 3, 1 << 4, 1 << 5, 1 << 6, 1 << 7
_BITS = DIRECTION_NEGATIVE | WITH_SWITCH | WITH_MARKER | MOVE_TO_HOME | RESET_COUNTER


def describe(configuration: int) -> str:
    """The manual's reading of a PNU 766 value (bits 3-7)."""
    searched = ((WITH_SWITCH, "home switch"), (WITH_MARKER, "marker pulse"))
    signals = [name for bit, name in searched if configuration & bit]
    direction = "negative" if configuration & DIRECTION_NEGATIVE else "positive"
    search = f"{' then '.join(signals)}, {direction} direction" if signals else "the current position (no search)"
    end = "move onto the home position" if configuration & MOVE_TO_HOME else "stop there"
    counter = "counter set to the homing offset (PNU 768)" if configuration & RESET_COUNTER else "counter kept"
    return f"PNU 766 = 0x{configuration:02X}: {search}; {end}; {counter}"


#: PNU 766 value → its description, for every composition of bits 3-7 (a search without a signal has no direction)
HOMING_CONFIGURATIONS: dict[int, str] = {
    value: describe(value)
    for value in range(0, _BITS + 1, DIRECTION_NEGATIVE)
    if not (value & DIRECTION_NEGATIVE and not value & (WITH_SWITCH | WITH_MARKER))
}
