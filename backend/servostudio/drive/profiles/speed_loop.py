"""The speed loop of a device family: which objects hold its gains and filters, and their scalings, by semantic names.

docs/control-loops.md §1–2 defines the loop and the scalings (the manual gives none): a gain's physical value is
``raw × unit``, times ``KJv/256`` for the gains the multiplier scales.  ``services.frequency.speed_loop`` converts
with this description only, so a new drive family describes its gains here and never in a service.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field


@dataclass(frozen=True)
class GainScale:
    """One gain object: physical value = raw × ``unit`` (× multiplier/``multiplier_one`` when ``scaled``)."""

    object: str
    unit: float
    scaled: bool = True


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
