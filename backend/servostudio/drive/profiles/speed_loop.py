"""The speed loop of a device family: which objects hold its gains and filters, and their scalings, by semantic names.

docs/control-loops.md §1–2 defines the loop and the scalings (the manual gives none): a gain's physical value is
``raw × unit``, times ``KJv/256`` for the gains the multiplier scales.  ``services.frequency.speed_loop`` converts
with this description only, so a new drive family describes its gains here and never in a service.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field


@dataclass(frozen=True)
class GainScale:
    """One gain object: physical value = raw × ``unit`` (× multiplier/``multiplier_one`` when ``scaled``)."""

    object: str
    unit: float
    scaled: bool = True


@dataclass(frozen=True)
class InertiaSetting:
    """A speed controller whose gains the drive derives itself from an inertia setting Θi (the encoTRive's
    0x2F02,8, p. 218; docs/identification.md § Tuning): with Kt = rated torque / rated current and the design
    crossover ωd = 1/((2π)²·Tc), KPv = Θi·ωd/Kt, KIv = KPv·ωd/``integral_divisor``, KAv = Θi/Kt, so the loop's
    crossover is (Θi/J)·ωd."""

    object: str
    #: kg·m² per count
    unit_kgm2: float
    #: Tc = 1/fc, the current controller's cycle in s
    cycle_s: float
    #: the motor rated torque (a count is ``rated_torque_unit`` N·m) and rated current (``rated_current_unit`` A)
    rated_torque: str
    rated_current: str
    rated_torque_unit: float = 1e-3
    rated_current_unit: float = 1e-3
    integral_divisor: float = 8.0
    #: κ of this loop, (bandwidth Hz, κ) with the crossover ωc = κ·2π·bandwidth, linear between, held beyond: its
    #: PI zero is fixed at ωd/8, not at ωc/4 as auto-tuning's rule has it (measured on the simulated encoTRive,
    #: hidden plants, from the shaft's step response; docs/identification.md)
    crossover_factors: tuple[tuple[float, float], ...] = (
        (20.0, 0.70), (30.0, 0.75), (40.0, 0.77), (65.0, 0.76), (85.0, 0.72), (110.0, 0.66), (140.0, 0.62)
    )  # fmt: skip

    @property
    def design_crossover(self) -> float:
        """ωd in rad/s."""
        return 1.0 / ((2.0 * math.pi) ** 2 * self.cycle_s)


@dataclass(frozen=True)
class SpeedLoopDescription:
    """What the speed-loop model needs of a drive family."""

    #: physical key (``kp_a_per_rad_s`` …) → the object and scaling of that gain
    gains: Mapping[str, GainScale]
    #: the gain multiplier (KJv, 256 = ×1); None: the drive has none (×1)
    multiplier: str | None = None
    multiplier_one: int = 256
    #: the first-order current-command filters in Hz (0 = off), in loop order
    current_filters: tuple[str, ...] = ()
    #: the speed-measurement filter (a code) and each code's time constant in s
    speed_filter: str | None = None
    speed_filter_s: Mapping[int, float] = field(default_factory=dict)
    #: the time constant of a speed filter that no object selects (the CD1-k's fixed one)
    fixed_speed_filter_s: float = 0.5e-3
    #: the motor's torque constant and the N·m/A of one count; None: the drive has no such object
    torque_constant: str | None = None
    torque_constant_unit: float = 1e-3
    control_period_s: float = 250e-6
    #: the gains are the drive's own function of this inertia setting (no gain objects); None: they are objects
    inertia_setting: InertiaSetting | None = None


#: the gain keys of the XtrapulsPac (docs/control-loops.md §2)
XTRAPULSPAC_SPEED_LOOP = SpeedLoopDescription(
    gains={
        "kp_a_per_rad_s": GainScale("kp_speed", 1e-4),
        "ki_a_per_rad": GainScale("ki_speed", 1e-2),
        "ki_leak_hz": GainScale("ki_speed_filter", 0.1, scaled=False),
        "kc_a_per_rad_s": GainScale("kc_speed", 1e-4),
        "kd_a_per_rad_s2": GainScale("kd_speed", 1e-6, scaled=False),
        "kd_filter_hz": GainScale("kd_speed_filter", 1.0, scaled=False),
        # the feed-forwards KBv / KAv (position modes only) share the multiplier: a new KJv rescales them too
        "kb_a_per_rad_s": GainScale("kb_position", 1e-4),
        "ka_a_per_rad_s2": GainScale("ka_position", 1e-6),
    },
    multiplier="kj_speed",
    current_filters=("current_filter_1", "current_filter_2", "current_filter_3"),
    speed_filter="speed_filter",
    speed_filter_s={0: 0.5e-3, 1: 1e-3, 2: 2e-3},
    torque_constant="motor_torque_constant",
)

#: the CD1-k: the same physical scalings on its own sub-indices, no multiplier, no leak, no filters
#: (docs/control-loops.md §2), and no torque-constant object
CD1K_SPEED_LOOP = SpeedLoopDescription(
    gains={
        "kp_a_per_rad_s": GainScale("kp_speed", 1e-4),
        "ki_a_per_rad": GainScale("ki_speed", 1e-2),
        "kc_a_per_rad_s": GainScale("kc_speed", 1e-4),
        "kd_a_per_rad_s2": GainScale("kd_speed", 1e-6, scaled=False),
        "kb_a_per_rad_s": GainScale("kb_position", 1e-4),
        "ka_a_per_rad_s2": GainScale("ka_position", 1e-6),
    },
)

#: the encoTRive: no gain objects, the drive derives its speed controller from the inertia setting Θi
#: (0x2F02,8 in 1e-7 kg·m², Tc = 100 µs: fc = 10 kHz, p. 219) and the motor rating 6076h (mN·m) / 6075h (mA);
#: its speed-measurement filter is fixed (the default 0.5 ms)
ENCOTRIVE_SPEED_LOOP = SpeedLoopDescription(
    gains={},
    inertia_setting=InertiaSetting("speed_controller_inertia", 1e-7, 1e-4, "rated_torque", "rated_current"),
)
