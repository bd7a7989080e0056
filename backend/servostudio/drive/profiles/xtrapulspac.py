"""Infranor XtrapulsPac: error words 0x3022, warnings 0x3024, Infranor code in EMCY byte 3, signatures, files."""

from __future__ import annotations

from servostudio.drive.profiles.base import (
    CIA301_OBJECTS,
    CIA402_MOTION_OBJECTS,
    CIA402_OBJECTS,
    Addressing,
    DeviceProfile,
    EmcyLayout,
)
from servostudio.drive.profiles.recorder import XTRAPULSPAC_RECORDER
from servostudio.drive.profiles.xtrapulspac_faults import ERRORS, WARNINGS
from servostudio.od.model import SaveType

XTRAPULSPAC = DeviceProfile(
    device="xtrapulspac",
    objects={
        **CIA301_OBJECTS,
        **CIA402_OBJECTS,
        "errors_low": (0x3022, 1),
        "errors_high": (0x3022, 2),
        "infranor_error_code": (0x3023, 4),
        "warnings": (0x3024, 0),
        "nmt_reset_configuration": (0x205D, 0),
        "sequence_number": (0x3610, 0),
        "sequence_parameters": (0x3611, 0),
        "max_sequences": (0x3612, 0),
        "target_velocity_source": (0x30FF, 0),
        "target_torque_source": (0x3071, 0),
        "speed_modulation_source": (0x3081, 0),
        "velocity_offset_source": (0x30B1, 0),
        "torque_offset_source": (0x30B2, 0),
        "torque_offset_2": (0x30B3, 0),
        "feedforward_speed": (0x31FF, 2),
        "feedforward_acceleration": (0x31FF, 3),
        "auto_phasing": (0x3413, 0),
        "motor_phasing": (0x3414, 0),
        "auto_tuning": (0x3426, 0),
        "motor_torque_constant": (0x6410, 11),
        "max_current": (0x6073, 0),
        "rated_current": (0x6075, 0),
        "pole_pairs": (0x3410, 1),
    },
    signatures={
        "save": ("store_parameters", "save"),
        "save_sequences": ("store_parameters", "sseq"),
        "load": ("restore_parameters", "load"),
        "load_user": ("restore_parameters", "lusr"),
        "load_sequences": ("restore_parameters", "lseq"),
        "merge_sequences": ("restore_parameters", "mseq"),
    },
    error_words=(("errors_low", 1), ("errors_high", 33)),
    warning_word="warnings",
    errors=ERRORS,
    warnings=WARNINGS,
    emcy_layout=EmcyLayout.CODE_BYTE,
    parameter_files={"DRIVEPAR.TXT": SaveType.DRIVEPAR, "USER_PAR.TXT": SaveType.USER_PAR},
    has_sequences=True,
    addressing=Addressing(
        range(1, 64),
        "XtrapulsPac node IDs are 1-63 (front-panel switches); n+64 is its redirected SDO channel (manual L2565-2589)",
        redirect_offset=64,
    ),
    # the reference sources (pointers: 0x30F10200 makes analog input 1 the target at once), the offsets added
    # after them and the external feed-forward references
    motion_objects=CIA402_MOTION_OBJECTS
    | {
        "target_velocity_source",
        "target_torque_source",
        "speed_modulation_source",
        "velocity_offset_source",
        "torque_offset_source",
        "torque_offset_2",
        "feedforward_speed",
        "feedforward_acceleration",
    },
    # phasing turns the rotor through an electrical turn or more, auto-tuning with current pulses (manual §3.5)
    moving_procedures={"auto_phasing": "apha", "motor_phasing": "mcal", "auto_tuning": "atun"},
    # error 64 "Procedure error" says only that one failed; what each needs non-zero (manual §3.2.2.2, §3.2.2.9):
    # the currents it drives the motor with, the pole pairs for motor phasing, the torque constant for auto-tuning
    procedure_fault=64,
    procedure_inputs={
        "auto_phasing": ("max_current", "rated_current"),
        "motor_phasing": ("max_current", "rated_current", "pole_pairs"),
        "auto_tuning": ("max_current", "rated_current", "motor_torque_constant"),
    },
    recorder=XTRAPULSPAC_RECORDER,
)
