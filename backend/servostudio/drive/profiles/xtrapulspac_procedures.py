"""The XtrapulsPac's procedures (manual §1.8.13, §1.8.16, §3.2.2, §4.2, §4.11; docs/control-loops.md §3–5).

Preconditions from the manual: phasing needs the drive disabled, no fault, no active limit switch (error 64
otherwise) and the power supply on; auto-tuning may also run enabled at standstill, and does not control the brake,
which must already be released (L983–986); no procedure starts while another one runs (status 1).
"""

from __future__ import annotations

from servostudio.drive.profiles.procedures import (
    IDENTIFIED_PLANT,
    OptionCodes,
    ProcedureDescription,
    ProcedureSet,
    UserUnits,
    phasing_procedures,
)

_PHASING_CHECKS = ("not_running", "disabled", "no_fault", "no_limit_switch", "dc_bus")
_CURRENTS = ("max_current", "rated_current")
CURRENT_GAINS = ("kp_current_q", "ki_current_q", "kp_current_d", "ki_current_d")
CURRENT_LIMITS = ("rated_current", "max_current")
TUNED = (
    "kp_speed",
    "ki_speed",
    "ki_speed_filter",
    "kc_speed",
    "kd_speed",
    "kd_speed_filter",
    "kj_speed",
    "kp_position",
    "kf_position",
    "ka_position",
    "kb_position",
    "speed_filter",
    "current_filter_1",
    "current_filter_2",
    "current_filter_3",
)
#: the auto-tuning options as the manual names them (0x3425,1..4)
TUNING_OPTIONS = {
    "bandwidth": OptionCodes("tuning_bandwidth", {"50": 0, "75": 1, "100": 2}),
    "filter": OptionCodes("tuning_filter", {"standard": 0, "anti-resonance": 1, "max-stiffness": 2}),
    "speed_filter": OptionCodes("tuning_speed_filter", {"auto": 0, "0.5": 1, "1": 2, "2": 3}),
    "mode": OptionCodes("tuning_requirement", {"min-following-error": 0, "min-overshoot": 1}),
}
#: what a verification move changes (and puts back)
VERIFICATION_OBJECTS = (
    "modes_of_operation",
    "target_velocity",
    "target_position",
    "profile_velocity",
    "max_profile_velocity",
    "profile_acceleration",
    "profile_deceleration",
)

XTRAPULSPAC_PROCEDURES = ProcedureSet(
    {
        **phasing_procedures(_PHASING_CHECKS, _CURRENTS),
        "current_loop": ProcedureDescription(
            "Current-loop calculation",
            "current_loop",
            "calc",
            moves=False,
            preconditions=("not_running", "disabled", "no_fault"),
            inputs=("control_inductance", "motor_stall_current", "motor_peak_current"),
            options={"regulator": OptionCodes("current_regulator_type", {"high": 0, "low": 1})},
            values={"inductance_mh": "motor_inductance"},
            results=CURRENT_GAINS,
            limits=CURRENT_LIMITS,
            duration_s=0.1,
            timeout_s=10.0,
        ),
        "current_limits": ProcedureDescription(
            "Current-limit calculation",
            "current_limits",
            "calc",
            moves=False,
            preconditions=("not_running", "disabled", "no_fault"),
            inputs=("motor_stall_current", "motor_peak_current"),
            limits=CURRENT_LIMITS,
            duration_s=0.1,
            timeout_s=10.0,
        ),
        "auto_tuning": ProcedureDescription(
            "Auto-tuning",
            "auto_tuning",
            "atun",
            moves=True,
            preconditions=(
                "not_running",
                "disabled_or_standstill",
                "no_fault",
                "no_limit_switch",
                "dc_bus",
                "brake_released",
            ),
            inputs=(*_CURRENTS, "motor_torque_constant"),
            options=TUNING_OPTIONS,
            results=TUNED,
            mode=1,
            duration_s=4.0,
            timeout_s=90.0,
        ),
    },
    units=UserUnits(4096, "position_factor_numerator", "position_factor_denominator"),
    identified=IDENTIFIED_PLANT,
    motor_inertia="motor_inertia",
    torque_constant="motor_torque_constant",
    speed_monitor_filter="velocity_monitor_filter",
    speed_measurement_filter="speed_filter",
    speed_measurement_filter_s={0: 0.5e-3, 1: 1e-3, 2: 2e-3},  # 0x30FA: 0.5 / 1 / 2 ms
    verification_objects=VERIFICATION_OBJECTS,
)
