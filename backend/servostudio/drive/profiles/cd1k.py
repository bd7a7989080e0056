"""Infranor CD1-k: drive error word 0x3020 (also in the EMCY manufacturer bytes), warnings 0x3021, no 0x603F;
'save' only with the drive disabled.

Source: the *CD1-k CANopen communication profile* (manual 001 in docs/devices.md): §2.1.7.1 "CD1-k specific error
field" (L546-579) for the faults, with bits 16-18 holding one coded power fault; §3.13.2 "Error and stop function"
(L3105-3177) for 0x3021 and the stop masks.  The manual gives no remedy column: each remedy below is the manual's
remark on the fault, with the objects its other chapters name for the same protection.
"""

from __future__ import annotations

from servostudio.drive.faults import CodedBits, FaultInfo
from servostudio.drive.profiles.base import (
    CIA301_OBJECTS,
    CIA402_MOTION_OBJECTS,
    CIA402_OBJECTS,
    Addressing,
    DeviceProfile,
    EmcyLayout,
)
from servostudio.drive.profiles.cd1k_procedures import CD1K_PROCEDURES
from servostudio.drive.profiles.homing import HOMING_METHODS
from servostudio.drive.profiles.io import CD1K_IO, CD1K_IO_MOTION_OBJECTS, CD1K_IO_OBJECTS
from servostudio.drive.profiles.procedures import IDENTIFIED_PLANT_OBJECTS
from servostudio.drive.profiles.speed_loop import CD1K_SPEED_LOOP

_STOP_MASKS = "Its stop (disable, stop 1 or stop 3) follows the masks 3330h / 3331h."

_ERRORS = {
    info.code: info
    for info in (
        FaultInfo(
            1,
            0,
            "Position limits",
            "A software position limit 607Dh was reached (active on a linear axis, 3360h = 1). In error mode "
            "(3361h = 0) reset the fault, then leave the limit with control word bit 11 'out of limit'. " + _STOP_MASKS,
        ),
        FaultInfo(
            2,
            0,
            "I²t",
            "The RMS current exceeded the rated current 6510h/6 (I²t monitor 30D5h; warning 3021h bit 1 first); "
            "6510h/7 selects limiting (0) or fusing (1). " + _STOP_MASKS,
        ),
        FaultInfo(
            3,
            0,
            "RDC / counting",
            "Position sensor counting error: 3217h bit 2 flags the position reference as lost; home the axis again, "
            "then clear 3217h.",
        ),
        FaultInfo(
            4,
            0,
            "Following error",
            "The position error exceeded the following error window 6065h (0 switches the protection off); "
            "detection mode 3033h. " + _STOP_MASKS,
        ),
        FaultInfo(5, 0, "EEPROM", "Parameter memory error."),
        FaultInfo(
            6,
            0,
            "Synchro_CAN",
            "SYNC lost or outside its window: the period 1006h (multiples of 500 µs) must match the master's SYNC "
            "within 3006h/1; the drive needs 180 ms of SYNC to lock. " + _STOP_MASKS,
        ),
        FaultInfo(
            7,
            0,
            "Low speed",
            "With the LOW SPEED input active the speed exceeded the low speed threshold 3310h. " + _STOP_MASKS,
        ),
        FaultInfo(
            8,
            0,
            "Procedure",
            "A procedure (auto-phasing 3410h, motor phasing 3414h, auto-tuning 3420h/2, …) failed; its result "
            "is not valid. Check what it needs and start it again.",
        ),
        FaultInfo(9, 0, "Current offset", "Not erasable."),
        FaultInfo(
            14,
            0,
            "Motor temperature",
            "The motor sensor 3321h passed the error threshold 3320h/2 (warning threshold 3320h/3, sensor type "
            "3320h/1). " + _STOP_MASKS,
        ),
        FaultInfo(15, 0, "Init 400 V", "Not erasable."),
        FaultInfo(16, 0, "Overcurrent", _STOP_MASKS),
        FaultInfo(
            20, 0, "IGBT", "Power module short circuit, PWM error, power module supply or temperature, or overcurrent."
        ),
        FaultInfo(21, 0, "Power-supply undervoltage", "Not stored: the fault list does not keep it."),
        FaultInfo(22, 0, "Resolver/encoder cable interruption", "Check the position sensor cable."),
        FaultInfo(25, 0, "Second-sensor cable interruption", "Check the second sensor's cable."),
        FaultInfo(26, 0, "Hall sensors / communication channel (absolute encoders)", "Check the sensor cable."),
    )
}

#: bits 18..16 of 0x3020: one power fault code (L570-579)
_POWER_FAULT = CodedBits(
    16,
    18,
    {
        value: FaultInfo(17, 0, f"Power fault: {name}", remedy)
        for value, name, remedy in (
            (0b010, "overvoltage", "The DC bus voltage (monitor 30E0h) is too high: check the braking resistor."),
            (
                0b011,
                "24 V error",
                "The 24 V supply is outside 18-29 V. Apply 24 V at least 5 s before the power supply and wait 30 s "
                "between off and on, else the error stays.",
            ),
            (0b100, "motor phase/ground short circuit", "Check the motor cable and windings."),
            (0b101, "braking resistor", "Short circuit or overload of the system braking resistor."),
            (0b110, "fan", "Fan system error."),
            (
                0b111,
                "motor brake",
                "A motor without a brake needs the manual brake control 60FEh/2 bit 0 = 1, else this error.",
            ),
        )
    },
)

#: 0x3021 warnings (code = bit + 1), §3.13.2.2
_WARNINGS = {
    info.code: info
    for info in (
        FaultInfo(2, 0, "I²t warning", "The I²t protection (6510h/6, 6510h/7) will act soon."),
        FaultInfo(4, 0, "Position following", "The position error approaches the following error window 6065h."),
        FaultInfo(10, 0, "Limit switch −", "The negative limit switch is active."),
        FaultInfo(11, 0, "Limit switch +", "The positive limit switch is active."),
        FaultInfo(12, 0, "Drive over-temperature", "Check the cooling of the drive."),
        FaultInfo(14, 0, "Motor over-temperature", "The motor sensor passed the warning threshold 3320h/3."),
    )
}

#: CiA 301/402 objects the manual lists as absent on the CD1-k (§4.11 end): no 0x603F, no heartbeat, no restore,
#: only 1018h/1, no 607Fh
_ABSENT = frozenset(
    {"error_code", "heartbeat_time", "restore_parameters", "product_code", "revision", "serial_number"}
    | {"max_profile_velocity"}
)

CD1K = DeviceProfile(
    device="cd1k",
    objects={
        **{name: address for name, address in {**CIA301_OBJECTS, **CIA402_OBJECTS}.items() if name not in _ABSENT},
        "drive_error_word": (0x3020, 0),
        "warning_word": (0x3021, 0),
        "auto_phasing": (0x3410, 0),
        "motor_phasing": (0x3414, 0),
        "auto_tuning": (0x3420, 2),
        "max_current_share": (0x6510, 5),
        "rated_current_share": (0x6510, 6),
        "pole_pairs": (0x6410, 2),
        # procedures (services.procedures; drive/profiles/cd1k_procedures.py)
        "phase_order": (0x6410, 3),
        "sensor_offset": (0x6410, 4),
        "kp_speed": (0x60F9, 1),
        "ki_speed": (0x60F9, 2),
        "kc_speed": (0x60F9, 4),
        "kd_speed": (0x60F9, 7),
        "kp_position": (0x60FB, 1),
        "kf_position": (0x60FB, 2),
        "ka_position": (0x60FB, 3),
        "kb_position": (0x60FB, 4),
        "tuning_bandwidth": (0x3420, 1),
        "tuning_requirement": (0x3430, 0),
        **IDENTIFIED_PLANT_OBJECTS,
        "digital_inputs": (0x60FD, 0),
        "digital_outputs": (0x60FE, 1),
        "digital_output_mask": (0x60FE, 2),
        "velocity_demand": (0x606B, 0),
        # 0x6078 in ‰ of the drive's current rating 6510h/4 (0.01 A), not of a motor rated current (docs/devices.md §9)
        "current_actual": (0x6078, 0),
        "drive_rating": (0x6510, 4),
        "encoder_increments": (0x608F, 1),
        **CD1K_IO_OBJECTS,
    },
    signatures={"save": ("store_parameters", "save")},
    error_words=(("drive_error_word", 1),),
    warning_word="warning_word",
    errors=_ERRORS,
    warnings=_WARNINGS,
    coded_error_bits=(_POWER_FAULT,),
    emcy_layout=EmcyLayout.BITFIELD,
    save_needs_disabled=True,
    addressing=Addressing(reason="CD1-k node IDs are 1-127 (switches)"),
    # phasing turns the rotor, auto-tuning moves it in position mode (CD1-k manual, L3979-4069)
    moving_procedures={"auto_phasing": "apha", "motor_phasing": "mcal", "auto_tuning": "atun"},
    # what a procedure needs non-zero: the currents it drives the motor with (% of the rating, 3FFFh = 100 %),
    # and for motor phasing the pole pairs auto-phasing found (L3975-4069)
    procedure_fault=8,
    procedure_inputs={
        "auto_phasing": ("max_current_share", "rated_current_share"),
        "motor_phasing": ("max_current_share", "rated_current_share", "pole_pairs"),
        "auto_tuning": ("max_current_share", "rated_current_share"),
    },
    procedures=CD1K_PROCEDURES,
    speed_loop=CD1K_SPEED_LOOP,
    current_reference="drive_rating",
    homing_methods=HOMING_METHODS,
    motion_objects=CIA402_MOTION_OBJECTS | CD1K_IO_MOTION_OBJECTS,
    io=CD1K_IO,
)
