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
from servostudio.drive.profiles.homing import HOMING_METHODS
from servostudio.drive.profiles.io import XTRAPULSPAC_IO, XTRAPULSPAC_IO_MOTION_OBJECTS, XTRAPULSPAC_IO_OBJECTS
from servostudio.drive.profiles.procedures import IDENTIFIED_PLANT_OBJECTS
from servostudio.drive.profiles.recorder import XTRAPULSPAC_RECORDER
from servostudio.drive.profiles.speed_loop import XTRAPULSPAC_SPEED_LOOP
from servostudio.drive.profiles.xtrapulspac_faults import ERRORS, WARNINGS
from servostudio.drive.profiles.xtrapulspac_procedures import XTRAPULSPAC_PROCEDURES
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
        # sequence mode (services.sequences, docs/sequences.md)
        "sequence_type": (0x3611, 1),
        "sequence_number_input": (0x3601, 1),
        "sequence_executed": (0x3601, 2),
        "sequence_conditional_input": (0x3601, 3),
        "sequence_outputs": (0x3602, 1),
        "sequence_dedicated_outputs": (0x3602, 3),
        "sequence_phase": (0x3605, 0),
        "sequence_captured_position": (0x360B, 0),
        "sequence_supported_types": (0x360F, 0),
        # simulator only (docs/sequences.md, Inputs): the levels wired to IN1..IN5, absent from the EDS
        "sim_physical_inputs": (0x5F00, 0),
        # position factor (manual §3.2.2.7): 4096 motor increments = numerator / denominator user units
        "position_factor_numerator": (0x6093, 1),
        "position_factor_denominator": (0x6093, 2),
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
        "current_actual": (0x6078, 0),
        "torque_actual": (0x6077, 0),
        "current_monitor_filter": (0x3078, 0),  # the frequency response opens it while it records 0x6078
        "pole_pairs": (0x3410, 1),
        # procedures (services.procedures; drive/profiles/xtrapulspac_procedures.py)
        "phase_order": (0x3410, 2),
        "sensor_offset": (0x3410, 3),
        "current_loop": (0x3411, 0),
        "current_limits": (0x3412, 0),
        "control_inductance": (0x340F, 0),
        "motor_stall_current": (0x6410, 9),
        "motor_peak_current": (0x6410, 10),
        "motor_inertia": (0x6410, 12),
        "motor_inductance": (0x6410, 13),
        "current_regulator_type": (0x60F6, 1),
        "kp_current_q": (0x60F6, 2),
        "ki_current_q": (0x60F6, 3),
        "kp_current_d": (0x60F6, 4),
        "ki_current_d": (0x60F6, 5),
        "kp_speed": (0x60F9, 2),
        "ki_speed": (0x60F9, 3),
        "ki_speed_filter": (0x60F9, 4),
        "kc_speed": (0x60F9, 5),
        "kd_speed": (0x60F9, 6),
        "kd_speed_filter": (0x60F9, 7),
        "kj_speed": (0x60F9, 8),
        "kp_position": (0x60FB, 2),
        "kf_position": (0x60FB, 3),
        "ka_position": (0x60FB, 4),
        "kb_position": (0x60FB, 5),
        "current_filter_1": (0x30F9, 1),
        "current_filter_2": (0x30F9, 2),
        "current_filter_3": (0x30F9, 3),
        "speed_filter": (0x30FA, 0),
        "tuning_bandwidth": (0x3425, 1),
        "tuning_filter": (0x3425, 2),
        "tuning_speed_filter": (0x3425, 3),
        "tuning_requirement": (0x3425, 4),
        **IDENTIFIED_PLANT_OBJECTS,
        "digital_inputs": (0x60FD, 0),
        "digital_outputs": (0x60FE, 1),
        "digital_output_mask": (0x60FE, 2),
        "dc_bus_voltage": (0x3408, 1),
        "dc_bus_minimum": (0x6510, 5),
        "velocity_demand": (0x606B, 0),
        "torque_slope": (0x6087, 0),
        "position_demand": (0x6062, 0),
        "velocity_monitor_filter": (0x306C, 0),
        **XTRAPULSPAC_IO_OBJECTS,
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
        # what sequence a start runs and the inputs its conditions test: they change what an enabled axis does
        "sequence_number_input",
        "sequence_conditional_input",
        "sim_physical_inputs",
    }
    | XTRAPULSPAC_IO_MOTION_OBJECTS,
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
    procedures=XTRAPULSPAC_PROCEDURES,
    speed_loop=XTRAPULSPAC_SPEED_LOOP,
    homing_methods=HOMING_METHODS,
    io=XTRAPULSPAC_IO,
)
