"""Where each semantic drive quantity lives in a device's dictionary, and the device's scalings.

The behaviour core speaks only semantic names ("target_position", "kp_speed", …); a `DeviceProfile` maps them to
(index, sub) for one device family. A name missing from a profile (or from the loaded EDS) means the device has
no such object and the behaviour uses its default.
"""

from __future__ import annotations

from dataclasses import dataclass, field

Address = tuple[int, int]

MODE_PP = 1
MODE_PV = 3
MODE_PT = 4
MODE_HM = 6
MODE_IP = 7
MODE_SQ = -3
"""XtrapulsPac sequence mode (docs/sequences.md)."""


@dataclass(frozen=True)
class DeviceProfile:
    key: str
    objects: dict[str, Address]
    modes: frozenset[int]
    procedures: dict[str, Address] = field(default_factory=dict)
    """Procedure name ('apha', 'mcal', 'calc', 'clim', 'atun') → trigger object."""
    supported_modes_word: int = 0
    default_mode: int = MODE_PP
    halt_bit: bool = True
    status_low_speed_bit14: bool = False

    def address(self, name: str) -> Address | None:
        return self.objects.get(name)


_COMMON_402: dict[str, Address] = {
    "control_word": (0x6040, 0),
    "status_word": (0x6041, 0),
    "mode": (0x6060, 0),
    "mode_display": (0x6061, 0),
    "supported_modes": (0x6502, 0),
    "error_code": (0x603F, 0),
    "position_demand": (0x6062, 0),
    "position_internal": (0x6063, 0),
    "position_actual": (0x6064, 0),
    "following_error_window": (0x6065, 0),
    "following_error_timeout": (0x6066, 0),
    "position_window": (0x6067, 0),
    "position_window_time": (0x6068, 0),
    "velocity_demand": (0x606B, 0),
    "velocity_actual": (0x606C, 0),
    "velocity_window": (0x606D, 0),
    "velocity_window_time": (0x606E, 0),
    "velocity_threshold": (0x606F, 0),
    "velocity_threshold_time": (0x6070, 0),
    "target_torque": (0x6071, 0),
    "max_current": (0x6073, 0),
    "torque_demand": (0x6074, 0),
    "rated_current": (0x6075, 0),
    "torque_actual": (0x6077, 0),
    "current_actual": (0x6078, 0),
    "dc_voltage_mv": (0x6079, 0),
    "target_position": (0x607A, 0),
    "home_offset": (0x607C, 0),
    "software_limit_min": (0x607D, 1),
    "software_limit_max": (0x607D, 2),
    "max_profile_velocity": (0x607F, 0),
    "max_motor_speed": (0x6080, 0),
    "profile_velocity": (0x6081, 0),
    "profile_acceleration": (0x6083, 0),
    "profile_deceleration": (0x6084, 0),
    "quick_stop_deceleration": (0x6085, 0),
    "quick_stop_code": (0x605A, 0),
    "shutdown_code": (0x605B, 0),
    "disable_operation_code": (0x605C, 0),
    "torque_slope": (0x6087, 0),
    "motion_profile_type": (0x6086, 0),
    "encoder_increments": (0x608F, 1),
    "position_factor_numerator": (0x6093, 1),
    "position_factor_denominator": (0x6093, 2),
    "homing_method": (0x6098, 0),
    "homing_speed_fast": (0x6099, 1),
    "homing_speed_slow": (0x6099, 2),
    "homing_acceleration": (0x609A, 0),
    "torque_offset": (0x60B2, 0),
    "ip_data": (0x60C1, 1),
    "sync_period": (0x1006, 0),
    "following_error_actual": (0x60F4, 0),
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
    "digital_inputs": (0x60FD, 0),
    "digital_outputs": (0x60FE, 1),
    "digital_output_mask": (0x60FE, 2),
    "target_velocity": (0x60FF, 0),
    "motor_type": (0x6402, 0),
    "motor_max_speed": (0x6410, 7),
    "motor_stall_current": (0x6410, 9),
    "motor_peak_current": (0x6410, 10),
    "motor_torque_constant": (0x6410, 11),
    "motor_inertia": (0x6410, 12),
    "motor_inductance": (0x6410, 13),
    "motor_pole_pairs": (0x6410, 14),
    "motor_phase": (0x6410, 15),
    "motor_offset": (0x6410, 16),
    "drive_max_current": (0x6510, 1),
    "drive_rated_current": (0x6510, 2),
    "undervoltage_threshold": (0x6510, 5),
}

IDENTIFIED_PLANT = {
    "identified_inertia": (0x3428, 1),
    "identified_viscous_friction": (0x3428, 2),
    "identified_coulomb_friction": (0x3428, 3),
    "identified_load_torque": (0x3428, 4),
    "identified_residual": (0x3428, 5),
}
"""0x3428 "Identified plant" (issue #13's contract), written by auto-tuning on the XtrapulsPac and the CD1-k."""

XTRAPULSPAC = DeviceProfile(
    key="xtrapulspac",
    objects=_COMMON_402
    | {
        "device_id": (0x200A, 1),
        "drive_voltage": (0x6510, 3),
        "operating_voltage": (0x6510, 4),
        "error_word_1": (0x3022, 1),
        "error_word_2": (0x3022, 2),
        "infranor_error_code": (0x3023, 4),
        "warning_word": (0x3024, 0),
        "error_inhibit_1": (0x3025, 1),
        "error_inhibit_2": (0x3025, 2),
        "error_stop2_1": (0x3025, 3),
        "error_stop2_2": (0x3025, 4),
        "error_stop3_1": (0x3025, 5),
        "error_stop3_2": (0x3025, 6),
        "status_bit8_link": (0x3044, 1),
        "status_bit14_link": (0x3044, 2),
        "inhibit_code": (0x305A, 0),
        "following_error_mode": (0x3065, 0),
        "velocity_rpm": (0x3069, 0),
        "velocity_monitor_filter": (0x306C, 0),
        "current_monitor_filter": (0x3078, 0),
        "speed_error_threshold": (0x306D, 0),
        "target_torque_source": (0x3071, 0),
        "ip_output": (0x30C1, 0),
        "torque_offset_2": (0x30B3, 0),
        "dynamic_current_limit": (0x30D1, 0),
        "dynamic_current_limit_config": (0x30D2, 0),
        "current_monitor": (0x30D4, 0),
        "current_filter_1": (0x30F9, 1),
        "current_filter_2": (0x30F9, 2),
        "current_filter_3": (0x30F9, 3),
        "speed_filter": (0x30FA, 0),
        "target_velocity_source": (0x30FF, 0),
        "homing_current_limit": (0x309C, 0),
        "end_on_home": (0x309D, 0),
        "homing_indicator": (0x3218, 0),
        "slow_down_ramp": (0x3300, 1),
        "stop_current_limit": (0x3301, 1),
        "stop_time_ramp": (0x3302, 1),
        "stop_time_current": (0x3302, 2),
        "drive_reaction_time": (0x3304, 0),
        "brake_reaction_time": (0x3305, 0),
        "motor_temperature": (0x3325, 0),
        "probe_type": (0x3324, 1),
        "probe_warning_celsius": (0x3324, 4),
        "probe_error_celsius": (0x3324, 5),
        "axis_type": (0x3360, 0),
        "i2t_mode": (0x3404, 1),
        "i2t_signal": (0x3404, 2),
        "i2t_current": (0x3404, 3),
        "dc_voltage_v": (0x3408, 1),
        "control_inductance": (0x340F, 0),
        "control_pole_pairs": (0x3410, 1),
        "control_phase": (0x3410, 2),
        "control_offset": (0x3410, 3),
        "tuning_bandwidth": (0x3425, 1),
        "tuning_filter_type": (0x3425, 2),
        "tuning_speed_filter": (0x3425, 3),
        "tuning_requirement": (0x3425, 4),
        **IDENTIFIED_PLANT,
        "device_status": (0x3441, 0),
    },
    modes=frozenset({1, 3, 4, 6, 7, MODE_SQ}),
    procedures={
        "calc": (0x3411, 0),
        "clim": (0x3412, 0),
        "apha": (0x3413, 0),
        "mcal": (0x3414, 0),
        "atun": (0x3426, 0),
    },
    supported_modes_word=0x0037006D,
)
