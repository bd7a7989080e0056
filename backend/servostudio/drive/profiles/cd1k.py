"""Infranor CD1-k: drive error word 0x3020 (also in the EMCY manufacturer bytes); 'save' only with the drive disabled.

Source: the CD1-k CANopen communication profile, L546–579 (manual 001 in docs/devices.md).  Bits 16–18 carry a
coded power fault.
"""

from __future__ import annotations

from servostudio.drive.faults import FaultInfo
from servostudio.drive.profiles.base import CIA301_OBJECTS, CIA402_OBJECTS, Addressing, DeviceProfile, EmcyLayout

_ERRORS = {
    info.code: info
    for info in (
        FaultInfo(1, 0, "Position limits", ""),
        FaultInfo(2, 0, "I²t", ""),
        FaultInfo(3, 0, "RDC / counting", ""),
        FaultInfo(4, 0, "Following error", ""),
        FaultInfo(5, 0, "EEPROM", ""),
        FaultInfo(6, 0, "Synchro_CAN", ""),
        FaultInfo(7, 0, "Low speed", ""),
        FaultInfo(8, 0, "Procedure", ""),
        FaultInfo(9, 0, "Current offset", "Not erasable."),
        FaultInfo(14, 0, "Motor temperature", ""),
        FaultInfo(15, 0, "Init 400 V", "Not erasable."),
        FaultInfo(16, 0, "Overcurrent", ""),
        FaultInfo(
            17,
            0,
            "Power fault (coded in bits 16–18)",
            "Bits 18..16: 010 overvoltage, 011 24 V error (outside "
            "18–29 V), 100 motor phase/ground short circuit, 101 braking resistor, 110 fan, 111 motor brake.",
        ),
        FaultInfo(18, 0, "Power fault (coded in bits 16–18)", "See bit 16."),
        FaultInfo(19, 0, "Power fault (coded in bits 16–18)", "See bit 16."),
        FaultInfo(20, 0, "IGBT", "Short circuit, PWM error, power module supply or temperature, overcurrent."),
        FaultInfo(21, 0, "Power-supply undervoltage", ""),
        FaultInfo(22, 0, "Resolver/encoder cable interruption", ""),
        FaultInfo(25, 0, "Second-sensor cable interruption", ""),
        FaultInfo(26, 0, "Hall sensors / communication channel (absolute encoders)", ""),
    )
}

CD1K = DeviceProfile(
    device="cd1k",
    objects={**CIA301_OBJECTS, **CIA402_OBJECTS, "drive_error_word": (0x3020, 0)},
    signatures={"save": ("store_parameters", "save")},
    error_words=(("drive_error_word", 1),),
    errors=_ERRORS,
    emcy_layout=EmcyLayout.BITFIELD,
    save_needs_disabled=True,
    addressing=Addressing(reason="CD1-k node IDs are 1-127 (switches)"),
)
