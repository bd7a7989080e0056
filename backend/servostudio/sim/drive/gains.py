"""Scalings of the regulator gains (0x60F6, 0x60F9, 0x60FB) and the tuning formulas built on them.

The manual gives no scaling (decisions.md §5): these definitions are the project's, written down with the same
formulas in docs/control-loops.md so the tool's tuning computes exactly what the simulated drive uses.
Physical units: A (d/q amplitude), V, rad and rad/s of the motor shaft, s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

CURRENT_KP_UNIT = 0.01
"""0x60F6,2 / ,4: current-loop proportional gain, V/A per count."""
CURRENT_KI_UNIT = 10.0
"""0x60F6,3 / ,5: current-loop integral gain, V/(A·s) per count."""
CURRENT_BANDWIDTH_HZ = {0: 500.0, 1: 250.0}
"""Current-loop bandwidth used by 'calc' for regulator type 0x60F6,1 = 0 (high) and 1 (low)."""

KPV_UNIT = 1e-4
"""0x60F9,2 KPv and 0x60F9,5 KCv and 0x60FB,5 KBv: A per rad/s."""
KIV_UNIT = 1e-2
"""0x60F9,3 KIv: A per rad (per integrated rad/s)."""
KIVF_UNIT_HZ = 0.1
"""0x60F9,4 KIvf: integrator leak corner, 0.1 Hz."""
KDV_UNIT = 1e-6
"""0x60F9,6 KDv: A per rad/s² (not scaled by KJv)."""
KJV_ONE = 256
"""0x60F9,8 KJv: multiplier KJv/256 on KPv, KIv, KCv, KBv, KAv."""
KPP_UNIT = 0.01
"""0x60FB,2 KPp: (rad/s) per rad, i.e. 1/s."""
KFP_FULL = 65535
"""0x60FB,3 KFp: speed feed-forward fraction KFp/65535."""
KAV_UNIT = 1e-6
"""0x60FB,4 KAv: A per rad/s² (scaled by KJv)."""

SPEED_FILTER_TAU = {0: 0.5e-3, 1: 1e-3, 2: 2e-3}
"""0x30FA: first-order speed-measurement filter time constant, s."""
TUNING_BANDWIDTH_HZ = {0: 50.0, 1: 75.0, 2: 100.0}
"""0x3425,1: auto-tuning speed-loop bandwidth."""
U16_MAX = 0xFFFF


@dataclass(frozen=True)
class CurrentGains:
    """Raw 0x60F6,2..5 values."""

    kp_q: int
    ki_q: int
    kp_d: int
    ki_d: int


def current_loop_gains(inductance_pp: float, regulator_type: int) -> CurrentGains:
    """'calc': Kp = Lφ·ωc, Ki = Kp·ωc/4 with Lφ = phase-to-phase inductance / 2, ωc = 2π·f (500 / 250 Hz)."""
    omega = 2.0 * math.pi * CURRENT_BANDWIDTH_HZ.get(regulator_type, CURRENT_BANDWIDTH_HZ[0])
    kp = inductance_pp / 2.0 * omega
    ki = kp * omega / 4.0
    kp_raw = _u16(kp / CURRENT_KP_UNIT)
    ki_raw = _u16(ki / CURRENT_KI_UNIT)
    return CurrentGains(kp_raw, ki_raw, kp_raw, ki_raw)


@dataclass(frozen=True)
class SpeedPositionGains:
    """Raw values of 0x60F9,2..8, 0x60FB,2..5 and 0x30FA chosen by tuning."""

    kpv: int
    kiv: int
    kivf: int
    kcv: int
    kdv: int
    kdvf: int
    kjv: int
    kpp: int
    kfp: int
    kav: int
    kbv: int
    speed_filter: int
    current_filters: tuple[int, int, int] = (0, 0, 0)
    """0x30F9,1..3 in Hz (0 = off)."""


CROSSOVER_FACTOR = {50.0: 0.667, 75.0: 0.643, 100.0: 0.611}
"""κ: the speed loop's gain crossover ωc = κ·2π·bandwidth. The PI zero at ωc/4, the speed-measurement filter, the
current loop and the control period's delay make the closed loop peak and reach −3 dB well above ωc (about 1.8·ωc);
κ was measured on the simulated loop (step response → frequency response) so that the −3 dB point lands on the
requested bandwidth with the "auto" speed filter (docs/control-loops.md §4)."""


def speed_loop_crossover(bandwidth_hz: float) -> float:
    """ωc in rad/s for a requested closed-loop bandwidth."""
    return CROSSOVER_FACTOR.get(bandwidth_hz, 0.64) * 2.0 * math.pi * bandwidth_hz


def speed_filter_for(bandwidth_hz: float) -> int:
    """0x30FA chosen by "auto": 0.5 ms for 75/100 Hz, 1 ms for 50 Hz."""
    return 0 if bandwidth_hz >= 75.0 else 1


ANTI_RESONANCE_CROSSOVER = 0.08
"""Anti-resonance: the crossover is at most 0.1 × the coupling resonance, ..."""
ANTI_RESONANCE_FILTER = 0.5
"""... the three current-command filters sit at 0.5 × the resonance, ..."""
ANTI_RESONANCE_INTEGRAL = 8.0
"""... and the PI zero moves down to ωc/8 to give back the phase those filters take at the crossover."""
ANTI_RESONANCE_FALLBACK = 4.0
"""Anti-resonance without an identified resonance: one filter at 4 × the bandwidth."""


def anti_resonance_design(bandwidth_hz: float, resonance_hz: float) -> tuple[float, float, tuple[int, int, int]]:
    """(ωc in rad/s, PI-zero divisor, 0x30F9,1..3) of the anti-resonance filter type (docs/control-loops.md §4).

    A load on an elastic coupling makes the motor see only its own inertia above the resonance, so the loop gain
    there is (J/Jm) times the rigid one, on top of the resonance peak: it must be attenuated (three first-order
    filters at half the resonance) and the crossover kept well below it (≤ resonance/10)."""
    crossover = speed_loop_crossover(bandwidth_hz)
    if resonance_hz <= 0.0:
        return crossover, 4.0, (round(ANTI_RESONANCE_FALLBACK * bandwidth_hz), 0, 0)
    crossover = min(crossover, ANTI_RESONANCE_CROSSOVER * 2.0 * math.pi * resonance_hz)
    corner = max(20, min(1000, round(ANTI_RESONANCE_FILTER * resonance_hz)))
    return crossover, ANTI_RESONANCE_INTEGRAL, (corner, corner, corner)


def tuned_gains(
    inertia: float,
    torque_constant: float,
    bandwidth_hz: float,
    *,
    position_loop: bool = True,
    minimum_following_error: bool = True,
    viscous_friction: float = 0.0,
    speed_filter: int | None = None,
    anti_resonance: bool = False,
    resonance_hz: float = 0.0,
) -> SpeedPositionGains:
    """The auto-tuning rule (docs/control-loops.md §4):

    ωc = κ·2π·bandwidth (CROSSOVER_FACTOR);
    KPv = J·ωc/Kt; KIv = KPv·ωc/4; KCv = 0; KPp = ωc/5;
    minimum following error: KFp = full, KBv = KCv + B/Kt (viscous compensation), KAv = J/Kt;
    minimum overshoot: KFp = KBv = KAv = 0; a velocity-mode tuning leaves the position gains at 0.
    anti-resonance: ωc, the PI zero and the current-command filters from `anti_resonance_design`.
    KJv is the smallest power-of-two multiple of 256 that keeps every scaled gain within U16.
    """
    selected = speed_filter_for(bandwidth_hz) if speed_filter is None else speed_filter
    omega, divisor, filters = speed_loop_crossover(bandwidth_hz), 4.0, (0, 0, 0)
    if anti_resonance:
        omega, divisor, filters = anti_resonance_design(bandwidth_hz, resonance_hz)
    kpv = inertia * omega / torque_constant
    kiv = kpv * omega / divisor
    kav = inertia / torque_constant if minimum_following_error else 0.0
    kbv = viscous_friction / torque_constant if minimum_following_error else 0.0
    scaled = (kpv / KPV_UNIT, kiv / KIV_UNIT, kav / KAV_UNIT, kbv / KPV_UNIT)
    kjv = KJV_ONE
    while max(scaled) * KJV_ONE / kjv > U16_MAX and kjv < U16_MAX // 2:
        kjv *= 2
    factor = KJV_ONE / kjv
    kpp = omega / 5.0 / KPP_UNIT if position_loop else 0.0
    return SpeedPositionGains(
        kpv=_u16(kpv / KPV_UNIT * factor),
        kiv=_u16(kiv / KIV_UNIT * factor),
        kivf=0,
        kcv=0,
        kdv=0,
        kdvf=0,
        kjv=kjv,
        kpp=_u16(kpp),
        kfp=KFP_FULL if (position_loop and minimum_following_error) else 0,
        kav=_u16(kav / KAV_UNIT * factor) if position_loop else 0,
        kbv=_u16(kbv / KPV_UNIT * factor) if position_loop else 0,
        speed_filter=selected,
        current_filters=filters,
    )


INERTIA_SETTING_UNIT = 1e-7
"""encoTRive 0x2F02,8 Θi: kg·m² per count (g·cm²; the manual's example motor has Θi = 510·10⁻⁷ kg·m², p. 218)."""
CURRENT_CYCLE_S = 1e-4
"""encoTRive Tc = 1/fc, the current controller's cycle: 10 kHz (the maximum ramp duration's 36 000 000 cycles of
1/fc are one hour, p. 219)."""
INERTIA_DESIGN_CROSSOVER = 1.0 / ((2.0 * math.pi) ** 2 * CURRENT_CYCLE_S)
"""ωd = 1/((2π)²·Tc) = 253 rad/s: the encoTRive speed loop's gain crossover when Θi equals the true inertia."""
INERTIA_INTEGRAL_DIVISOR = 8.0
"""The encoTRive speed controller's PI zero at ωd/8."""


@dataclass(frozen=True)
class InertiaSpeedGains:
    """The encoTRive speed controller derived from Θi (physical units: A per rad/s, A per rad, A per rad/s², 1/s)."""

    kpv: float
    kiv: float
    kav: float
    kpp: float


def inertia_speed_gains(inertia_setting: float, rated_torque: float, rated_current: float) -> InertiaSpeedGains:
    """The encoTRive's speed controller from its inertia setting Θi (kg·m²), 6076h MN (N·m) and 6075h iN (A, the
    sine peak), docs/identification.md § Tuning (p. 218, the project's reading, decisions.md §6):

    KP = Θi·iN / (MN·iM·2π·Tc) is the drive's gain in current measuring ranges iM per rev/s of speed error, so in A
    per rad/s KPv = KP·iM/2π = Θi / (Kt·(2π)²·Tc) with Kt = MN/iN (iM cancels); the loop's crossover is
    (Θi/J)·ωd.  The manual gives no integral or position gain: the PI zero at ωd/8 (a loaded axis on the factory's
    Θi, the rotor's alone, crosses over below ωd and keeps its phase margin), KPp = ωd/10 (below the speed loop down
    to Θi ≈ J/5), and the acceleration feed-forward KAv = Θi/Kt; the drive knows no friction (KBv = 0)."""
    if rated_torque <= 0 or rated_current <= 0:
        return InertiaSpeedGains(0.0, 0.0, 0.0, 0.0)
    torque_constant = rated_torque / rated_current
    kpv = inertia_setting * INERTIA_DESIGN_CROSSOVER / torque_constant
    return InertiaSpeedGains(
        kpv=kpv,
        kiv=kpv * INERTIA_DESIGN_CROSSOVER / INERTIA_INTEGRAL_DIVISOR,
        kav=inertia_setting / torque_constant,
        kpp=INERTIA_DESIGN_CROSSOVER / 10.0,
    )


def _u16(value: float) -> int:
    return max(0, min(U16_MAX, round(value)))
