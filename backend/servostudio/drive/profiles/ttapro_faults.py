"""The TTA-PRO's faults and warnings with the manual's texts (TTA-PRO Profibus Communication Profile, Chapter 3:
PNU 773 L1792-1831, PNU 778 L1856-1868, PNU 873 L2856-2870), as the fault report decodes them
(``drive.control.fault_report``, ``DeviceProfile.error_words``).

Codes are the bit number + 1, as for the CANopen drives: PNU 773 (3 bytes, byte 1 the low one) gives codes 1..24,
PNU 778 codes 101..116 with its bits 0-2 holding one power-stage fault code; PNU 873 gives warnings 1..16. The
manual names each fault and says what it means; it prints no remedy, so the remedy says where the details are or
what the fault acknowledge (CW7) needs. The drive has no CiA 402 error codes (0).
"""

from __future__ import annotations

from servostudio.drive.faults import CodedBits, FaultInfo

POSITIONER_ERRORS_FIRST = 1
"""Code of PNU 773 bit 0."""
POWER_STAGE_FIRST = 101
"""Code of PNU 778 bit 0."""

_ACKNOWLEDGE = "remove the cause, then acknowledge the fault (control word bit 7, POST …/faults/reset)"

_773: dict[int, tuple[str, str]] = {  # code = bit + 1 (I²t is bit 1 of byte 1)
    2: ("I²t: I²t protection", "the motor current stayed above the rated current (PNU 711) too long"),
    3: ("RDC / COUNT: resolver converter error / encoder counting error", ""),
    4: ("POS: position following error", "the following error exceeded its window (PNU 741)"),
    5: ("MEM: parameters / sequences / cogging memory error", ""),
    6: ("BUS: PROFIBUS-DP mode error", "the master stopped the cyclic exchange while PROFIBUS controlled"),
    8: ("BUSY: procedure error", "a procedure (PNU 704, 729, 736, 780, 781, …) failed"),
    9: ("2nd SENSOR: 2nd position sensor cable interruption error", ""),
    10: ("POWER: power stage error", "PNU 778 names the power-stage fault"),
    11: ("RES / COD / HES: resolver / encoder / Hall sensor cable interruption error", ""),
    12: ("AP: power undervoltage error", ""),
    13: ("24V: 24 V error", ""),
    14: ("TMOT: motor temperature error", ""),
    15: ("CDG: watchdog error", ""),
    17: ("HOME: homing procedure timeout error", ""),
    18: ("E2PPAR: parameters EEPROM checksum error", "write the parameters again and save them (PNU 729)"),
    19: ("E2PSEQ: sequences EEPROM checksum error", "write the sequence table again with its checksum"),
    20: ("E2PCOG: cogging torque memory checksum error", ""),
    21: ("SEQWR: sequence writing error", ""),
}
_778: dict[int, tuple[str, str]] = {
    104: ("IGBT module error", ""),
    105: ("Power undervoltage (no influence on the AOK signal)", ""),
    110: ("400 V power stage initialization error", ""),
    111: ("Power configuration error", ""),
    112: ("Current measurement offset error", ""),
    116: ("Current error", ""),
}
_778_CODES: dict[int, str] = {
    2: "Power voltage error",
    3: "Out of 24 Vdc range (18 V to 29 V)",
    4: "Motor phases/earth short-circuit",
    5: "Braking system error",
    6: "Fan error",
    7: "Motor holding brake error",
}
_873: dict[int, str] = {
    2: "I²t protection",
    12: "°C drive: drive temperature",
    14: "°C motor: motor temperature",
}


def _remedy(meaning: str) -> str:
    return f"{meaning}; {_ACKNOWLEDGE}" if meaning else _ACKNOWLEDGE[0].upper() + _ACKNOWLEDGE[1:]


ERRORS: dict[int, FaultInfo] = {
    code: FaultInfo(code, 0, name, _remedy(meaning)) for code, (name, meaning) in (_773 | _778).items()
}
POWER_STAGE_CODE = CodedBits(
    0,
    2,
    {value: FaultInfo(POWER_STAGE_FIRST, 0, name, _remedy("")) for value, name in _778_CODES.items()},
    word=POWER_STAGE_FIRST,
)
"""PNU 778 bits 0-2: one power-stage fault code."""
WARNINGS: dict[int, FaultInfo] = {
    code: FaultInfo(code, 0, name, "a warning: the drive keeps running (PNU 899 selects which set ZSW bit 7)")
    for code, name in _873.items()
}
