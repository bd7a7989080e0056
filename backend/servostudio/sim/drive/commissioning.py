"""What a commissioned drive holds for its plant, and the current-limit rule of 'calc' / 0x3412.

A drive started without a plant file or seed is "in service": motor data, phasing and gains match the plant.
These values are written over the dictionary defaults (never over values the node loaded from DRIVEPAR.TXT).
"""

from __future__ import annotations

from servostudio.sim.drive import gains
from servostudio.sim.plant import Plant

COMMISSIONING_BANDWIDTH_HZ = 100.0


def current_limits(stall_ma: float, peak_ma: float, drive_max_ma: float, drive_rated_ma: float) -> tuple[int, int]:
    """0x3412 rule: rated 0x6075 = min(motor stall, drive rated) mA; max 0x6073 = min(peak, drive max) in ‰ of it."""
    rated = min(v for v in (stall_ma, drive_rated_ma) if v > 0) if (stall_ma > 0 or drive_rated_ma > 0) else 0.0
    peak = min(v for v in (peak_ma, drive_max_ma) if v > 0) if (peak_ma > 0 or drive_max_ma > 0) else 0.0
    if rated <= 0:
        return 0, 0
    return round(rated), min(32767, round(1000.0 * peak / rated))


def commissioned_values(plant: Plant, drive_max_ma: float, drive_rated_ma: float) -> dict[str, int]:
    """Semantic name → raw value of everything commissioning sets for `plant`."""
    rated, maximum = current_limits(plant.stall_current * 1000, plant.peak_current * 1000, drive_max_ma, drive_rated_ma)
    current = gains.current_loop_gains(plant.inductance, 0)
    tuned = gains.tuned_gains(
        plant.total_inertia,
        plant.torque_constant,
        COMMISSIONING_BANDWIDTH_HZ,
        viscous_friction=plant.viscous_friction,
    )
    return {
        "motor_max_speed": plant.max_speed_rpm,
        "motor_stall_current": round(plant.stall_current * 1000),
        "motor_peak_current": round(plant.peak_current * 1000),
        "motor_torque_constant": round(plant.torque_constant * 1000),
        "motor_inertia": round(plant.motor_inertia * 1e6),
        "motor_inductance": round(plant.inductance * 1e4),
        "motor_pole_pairs": plant.pole_pairs,
        "motor_phase": plant.phase_order,
        "motor_offset": plant.sensor_offset,
        "control_pole_pairs": plant.pole_pairs,
        "control_phase": plant.phase_order,
        "control_offset": plant.sensor_offset,
        "control_inductance": round(plant.inductance * 1e4),
        "max_motor_speed": plant.max_speed_rpm,
        "rated_current": rated,
        "max_current": maximum,
        "kp_current_q": current.kp_q,
        "ki_current_q": current.ki_q,
        "kp_current_d": current.kp_d,
        "ki_current_d": current.ki_d,
        "kp_speed": tuned.kpv,
        "ki_speed": tuned.kiv,
        "ki_speed_filter": tuned.kivf,
        "kc_speed": tuned.kcv,
        "kd_speed": tuned.kdv,
        "kd_speed_filter": tuned.kdvf,
        "kj_speed": tuned.kjv,
        "kp_position": tuned.kpp,
        "kf_position": tuned.kfp,
        "ka_position": tuned.kav,
        "kb_position": tuned.kbv,
        "speed_filter": tuned.speed_filter,
    }
