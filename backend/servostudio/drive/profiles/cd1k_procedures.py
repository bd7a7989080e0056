"""The CD1-k's procedures (CD1-k CANopen manual L3975–4069): auto-phasing on 0x3410, motor phasing on 0x3414,
auto-tuning on 0x3420,2 with bandwidth and filter in one code 0x3420,1 (3 × filter + bandwidth) and the application
requirement in 0x3430; no current-loop calculation, no speed-filter choice, no motor inertia or torque constant in
its motor data.
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

_PHASING_CHECKS = ("not_running", "disabled", "no_fault", "no_limit_switch")
_CURRENTS = ("max_current_share", "rated_current_share")
TUNED = (
    "kp_speed",
    "ki_speed",
    "kc_speed",
    "kd_speed",
    "kp_position",
    "kf_position",
    "ka_position",
    "kb_position",
)

CD1K_PROCEDURES = ProcedureSet(
    {
        **phasing_procedures(_PHASING_CHECKS, _CURRENTS),
        "auto_tuning": ProcedureDescription(
            "Auto-tuning",
            "auto_tuning",
            "atun",
            moves=True,
            preconditions=("not_running", "disabled_or_standstill", "no_fault", "no_limit_switch", "brake_released"),
            inputs=_CURRENTS,
            options={
                "bandwidth": OptionCodes("tuning_bandwidth", {"50": 0, "75": 1, "100": 2}),
                "filter": OptionCodes("tuning_bandwidth", {"standard": 0, "anti-resonance": 3, "max-stiffness": 6}),
                "mode": OptionCodes("tuning_requirement", {"min-following-error": 0, "min-overshoot": 1}),
            },
            results=TUNED,
            mode=1,
            duration_s=4.0,
            timeout_s=90.0,
        ),
    },
    units=UserUnits("encoder_increments"),
    identified=IDENTIFIED_PLANT,
    identified_per_ampere=True,
    verification_objects=(
        "modes_of_operation",
        "target_velocity",
        "target_position",
        "profile_velocity",
        "profile_acceleration",
        "profile_deceleration",
    ),
)
