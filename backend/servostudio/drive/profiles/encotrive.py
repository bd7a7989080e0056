"""TR-Electronic encoTRive MD-025: standard CiA 301/402 objects; faults only as EMCY / 0x603F codes.

Source: the *encoTRive MD-025 CANopen* user manual (manual 004 in docs/devices.md): the manufacturer EMCY bytes are
unused (§ EMCY, p. 157); the error codes and their texts (pp. 253-260, Table 34 and the manufacturer table).  A
code the manual gives no text of its own (0x2310 continuous over-current, …) is a CiA 301/402 code: it is shown by
its standard name, with the manual's error register class and its general rule for acknowledging an error.
"""

from __future__ import annotations

import math

from servostudio.drive.faults import FaultInfo
from servostudio.drive.profiles.base import (
    CIA301_OBJECTS,
    CIA402_OBJECTS,
    CIA402_TORQUE_OBJECTS,
    Addressing,
    DeviceProfile,
)
from servostudio.drive.profiles.io import ENCOTRIVE_IO
from servostudio.drive.profiles.procedures import ProcedureSet, UserUnits
from servostudio.drive.profiles.speed_loop import ENCOTRIVE_SPEED_LOOP

_EMCY = {
    info.cia402_code: info
    for info in (
        FaultInfo(
            0,
            0x4280,
            "CPU-board temperature sensor failed",
            "The drive switched off; reset with control word bit 7 once the sensor works.",
        ),
        FaultInfo(0, 0x4290, "CPU-board over-temperature (warning)", "Clears by itself below the warning threshold."),
        FaultInfo(0, 0x4310, "Power-stage over-temperature", ""),
        FaultInfo(0, 0x6343, "Ramp positioning lasted longer than the maximum ramp duration", ""),
        FaultInfo(0, 0x8100, "Communication error", ""),
        FaultInfo(0, 0x8110, "CAN buffer overflow or wrong state (e.g. TPDO rate too high)", ""),
        FaultInfo(0, 0x8120, "CAN error-passive", ""),
        FaultInfo(0, 0x8130, "Life-guard or heartbeat error", ""),
        FaultInfo(0, 0x8140, "CAN active again after bus-off", "Not cleared automatically."),
        FaultInfo(0, 0x8150, "COB-ID collision", "A SYNC/PDO COB-ID is used twice on the node; reception is blocked."),
        FaultInfo(0, 0x8200, "Protocol error", ""),
        FaultInfo(0, 0x8210, "PDO ignored (length error)", ""),
        FaultInfo(0, 0x8220, "PDO length exceeded", ""),
        FaultInfo(
            0,
            0x8611,
            "Following error",
            "The error exceeded 0x6065 for longer than 0x6066; check the supply voltage and the load.",
        ),
    )
}

#: what the manual says of every error (p. 253-254): the error register 1001h shows its class, 1003h its code
_ACKNOWLEDGE = (
    "The error register 1001h shows its class (bit 1 current, 2 voltage, 3 temperature, 4 communication) and 1003h "
    "the history. Remove the cause, then acknowledge with control word bit 7: the drive goes to switch-on disabled."
)

#: positioning ramp (1) and speed ramp (3): each ramp and speed is limited by its maximum (Table 16, Table 19);
#: a 0 in any of them keeps the axis still without a fault
_RAMP_LIMITS = ("profile_acceleration", "max_acceleration", "profile_deceleration", "max_deceleration")

_RPM = 2.0 * math.pi / 60.0

_VERIFICATION_OBJECTS = (
    "modes_of_operation",
    "target_velocity",
    "target_position",
    "profile_velocity",
    "profile_acceleration",
    "profile_deceleration",
    "max_profile_velocity",
    "max_acceleration",
    "max_deceleration",
)

ENCOTRIVE = DeviceProfile(
    device="encotrive",
    objects={
        **CIA301_OBJECTS,
        **CIA402_OBJECTS,
        **CIA402_TORQUE_OBJECTS,
        "error_history": (0x1003, 1),
        "max_acceleration": (0x60C5, 0),
        "max_deceleration": (0x60C6, 0),
        "digital_inputs": (0x60FD, 0),
        "digital_outputs": (0x60FE, 1),
        "digital_output_mask": (0x60FE, 2),
        "encoder_increments": (0x608F, 1),
        "position_factor_numerator": (0x6093, 1),
        "position_factor_denominator": (0x6093, 2),
        # Θi, from which the drive computes its speed controller (p. 218; index: decisions.md §6)
        "speed_controller_inertia": (0x2F02, 8),
    },
    signatures={"save": ("store_parameters", "save"), "load": ("restore_parameters", "load")},
    emcy_codes=_EMCY,
    error_code_remedy=_ACKNOWLEDGE,
    addressing=Addressing(reason="encoTRive node IDs are 1-127"),
    #: the factory velocity and acceleration factors 6094h / 6097h: speeds in rpm, accelerations in rpm/s (Formula 8-11)
    speed_unit_rad_s=_RPM,
    acceleration_unit_rad_s2=_RPM,
    mode_limits={
        1: ("profile_velocity", "max_profile_velocity", *_RAMP_LIMITS),
        3: ("max_profile_velocity", *_RAMP_LIMITS),
    },
    io=ENCOTRIVE_IO,
    #: no procedures; what a tuning's verification step changes, restored after it
    procedures=ProcedureSet(
        {},
        units=UserUnits("encoder_increments", "position_factor_numerator", "position_factor_denominator"),
        verification_objects=_VERIFICATION_OBJECTS,
    ),
    speed_loop=ENCOTRIVE_SPEED_LOOP,
)
