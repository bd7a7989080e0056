"""Homing methods (0x6098) with the manual's description of each, for the quick test's method picker.

Source: XtrapulsPac CANopen manual §3.2.3.4 (the table of supported methods, L8921–8974, and the method 8 worked
example) and the CD1-k CANopen profile §3.4 (L2069–2241), which supports the same numbers: CiA 402 methods 1–14,
17–30, 33–35 and the manufacturer's mechanical-stop methods −1..−4; 15, 16, 31 and 32 are not supported.
"Exterior / interior" is the side of the switch on which the index pulse is searched.
"""

from __future__ import annotations

_SWITCHES = {
    1: ("Negative limit switch", ""),
    2: ("Positive limit switch", ""),
    3: ("Positive home switch", ""),
    4: ("Positive home switch", ""),
    5: ("Negative home switch", ""),
    6: ("Negative home switch", ""),
    7: ("Home switch, negative side", "positive initial move, reverses on the positive limit switch"),
    8: ("Home switch, negative side", "positive initial move, reverses on the positive limit switch"),
    9: ("Home switch, positive side", "positive initial move, reverses on the positive limit switch"),
    10: ("Home switch, positive side", "positive initial move, reverses on the positive limit switch"),
    11: ("Home switch, positive side", "negative initial move, reverses on the negative limit switch"),
    12: ("Home switch, positive side", "negative initial move, reverses on the negative limit switch"),
    13: ("Home switch, negative side", "negative initial move, reverses on the negative limit switch"),
    14: ("Home switch, negative side", "negative initial move, reverses on the negative limit switch"),
}
#: where the index pulse is searched by methods 1–14 (17–30 are the same without the index pulse)
_INDEX_SIDE = {1: "exterior", 2: "exterior", 3: "exterior", 4: "interior", 5: "exterior", 6: "interior"}
_INDEX_SIDE |= {7: "exterior", 8: "interior", 9: "interior", 10: "exterior", 11: "exterior", 12: "interior"}
_INDEX_SIDE |= {13: "interior", 14: "exterior"}


def _described(number: int, index: bool) -> str:
    switch, moves = _SWITCHES[number]
    pulse = f"index pulse {_INDEX_SIDE[number]}" if index else f"no index pulse (method {number} without it)"
    return "; ".join(part for part in (f"{switch}, {pulse}", moves) if part)


#: method number → the manual's description
HOMING_METHODS: dict[int, str] = {
    **{number: _described(number, index=True) for number in _SWITCHES},
    **{number + 16: _described(number, index=False) for number in _SWITCHES},
    33: "First index pulse, negative initial move (no switch)",
    34: "First index pulse, positive initial move (no switch)",
    35: "Homing on the current position (allowed even when not in Operation enabled)",
    -1: "Mechanical limit, negative move, then the first index pulse (current limited by 0x309C)",
    -2: "Mechanical limit, positive move, then the first index pulse (current limited by 0x309C)",
    -3: "Mechanical limit, negative move, no index pulse (current limited by 0x309C)",
    -4: "Mechanical limit, positive move, no index pulse (current limited by 0x309C)",
}
