"""The hidden plant of one simulated axis: motor, sensor, mechanics, switches, DC bus, thermal constants.

The drive model never reads these values as parameters: it only sees what its sensors report. The plant is
the "truth" that commissioning (auto-phasing, auto-tuning, current-loop calculation) has to discover.
Keys and units are listed in docs/sim-plant.md. All values are SI (rad, s, A, V, N·m, kg·m², Ω, H, K);
switch and stop positions are motor revolutions measured on the load side.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import random
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

PHASE_240 = 0x5555
"""0x3410,2 value "240°" (phase order U-V-W)."""
PHASE_120 = 0xAAAA
"""0x3410,2 value "120°" (phase order U-W-V)."""

FEEDBACK_RESOLVER = "resolver"
FEEDBACK_ENCODER = "encoder"
"""Incremental encoder without Hall sensors: motor phasing ('mcal') is needed after every power-up."""


class PlantError(ValueError):
    """A plant description that cannot be used; the message names the file and the key."""


@dataclass(frozen=True)
class Plant:
    """One axis' physical truth. Defaults describe a small, plausible servo axis."""

    # motor
    pole_pairs: int = 4
    phase_order: int = PHASE_240
    sensor_offset: int = 0x2A00
    torque_constant: float = 0.60
    phase_resistance: float = 1.2
    inductance: float = 6.0e-3
    motor_inertia: float = 1.2e-4
    peak_current: float = 9.0
    stall_current: float = 3.0
    max_speed_rpm: int = 4000
    # sensor
    feedback: str = FEEDBACK_RESOLVER
    encoder_counts: int = 65536
    index_position: float = 0.25
    # mechanics (load side)
    load_inertia: float = 2.4e-4
    viscous_friction: float = 2.0e-4
    coulomb_friction: float = 0.05
    gravity_torque: float = 0.0
    coupling_stiffness: float = 0.0
    coupling_damping: float = 0.0
    brake_torque: float = 3.0
    has_brake: bool = False
    initial_position: float = 0.0
    # switches and stops (None = not fitted)
    negative_limit_switch: float | None = -20.0
    positive_limit_switch: float | None = 20.0
    home_switch: tuple[float, float] | None = (3.0, 6.0)
    negative_hard_stop: float | None = -21.0
    positive_hard_stop: float | None = 21.0
    # power stage
    dc_bus_voltage: float = 325.0
    dc_bus_capacitance: float = 470e-6
    supply_resistance: float = 0.5
    braking_resistance: float = 50.0
    braking_on_voltage: float = 380.0
    overvoltage: float = 420.0
    mains_on: bool = True
    # thermal
    ambient_temperature: float = 25.0
    thermal_resistance: float = 1.5
    thermal_time_constant: float = 600.0

    notes: dict[str, Any] = field(default_factory=dict, compare=False)

    def __post_init__(self) -> None:
        problems = _validate(self)
        if problems:
            raise PlantError("; ".join(problems))

    # -- derived quantities ---------------------------------------------------------------------------------------

    @property
    def two_mass(self) -> bool:
        """True when the load hangs on an elastic coupling (a resonance) instead of being rigid."""
        return self.coupling_stiffness > 0.0

    @property
    def total_inertia(self) -> float:
        return self.motor_inertia + self.load_inertia

    @property
    def phase_sign(self) -> int:
        """+1 for phase order 0x5555, -1 for 0xAAAA: the direction the field turns for a rising angle."""
        return 1 if self.phase_order == PHASE_240 else -1

    # -- construction ---------------------------------------------------------------------------------------------

    @classmethod
    def commissioned(cls) -> Plant:
        """The default axis of a "machine in service": the drive is set up for exactly this plant."""
        return cls()

    @classmethod
    def from_seed(cls, seed: int) -> Plant:
        """A random but plausible axis; the same seed always gives the same plant."""
        rng = random.Random(seed)
        kt = round(rng.uniform(0.3, 1.2), 3)
        stall = round(rng.uniform(2.0, 6.0), 2)
        motor_inertia = round(rng.uniform(4e-5, 4e-4), 7)
        two_mass = rng.random() < 0.3
        load_inertia = round(motor_inertia * rng.uniform(0.0, 5.0), 7)
        resonance_hz = rng.uniform(60.0, 250.0)
        reduced = motor_inertia * load_inertia / (motor_inertia + load_inertia) if load_inertia else 0.0
        stiffness = round(reduced * (2 * math.pi * resonance_hz) ** 2, 2) if two_mass and reduced else 0.0
        lower = rng.uniform(-15.0, -5.0)
        upper = rng.uniform(5.0, 15.0)
        home_low = rng.uniform(lower + 2.0, upper - 4.0)
        return cls(
            pole_pairs=rng.choice((2, 3, 4, 5, 6)),
            phase_order=rng.choice((PHASE_240, PHASE_120)),
            sensor_offset=rng.randrange(0, 65536),
            torque_constant=kt,
            phase_resistance=round(rng.uniform(0.4, 3.0), 3),
            inductance=round(rng.uniform(2e-3, 15e-3), 5),
            motor_inertia=motor_inertia,
            peak_current=round(stall * rng.uniform(2.5, 3.5), 2),
            stall_current=stall,
            max_speed_rpm=_reachable_speed_rpm(kt, 325.0),
            index_position=round(rng.random(), 4),
            load_inertia=load_inertia,
            viscous_friction=round(rng.uniform(5e-5, 5e-4), 6),
            coulomb_friction=round(kt * stall * rng.uniform(0.01, 0.05), 4),
            coupling_stiffness=stiffness,
            coupling_damping=round(2 * 0.05 * math.sqrt(stiffness * reduced), 5) if stiffness else 0.0,
            initial_position=round(rng.uniform(lower + 1.0, upper - 1.0), 3),
            negative_limit_switch=round(lower, 3),
            positive_limit_switch=round(upper, 3),
            home_switch=(round(home_low, 3), round(home_low + rng.uniform(1.0, 3.0), 3)),
            negative_hard_stop=round(lower - 1.0, 3),
            positive_hard_stop=round(upper + 1.0, 3),
            notes={"seed": seed},
        )

    @classmethod
    def from_mapping(cls, data: dict[str, Any], source: str = "<plant>") -> Plant:
        """Build from a JSON object; unknown keys and wrong types are errors naming `source` and the key."""
        known = {f.name: f for f in dataclasses.fields(cls)}
        kwargs: dict[str, Any] = {}
        for key, value in data.items():
            if key not in known or key == "notes":
                raise PlantError(f"{source}: unknown key {key!r} (see docs/sim-plant.md)")
            kwargs[key] = _coerce(key, value, known[key].type, source)
        try:
            return cls(**kwargs)
        except PlantError as exc:
            raise PlantError(f"{source}: {exc}") from None

    @classmethod
    def from_json(cls, path: Path) -> Plant:
        try:
            text = path.read_text(encoding="utf-8")
        except OSError as exc:
            raise PlantError(f"{path}: cannot read ({exc.strerror})") from None
        try:
            data = json.loads(text)
        except json.JSONDecodeError as exc:
            raise PlantError(f"{path}:{exc.lineno}: invalid JSON ({exc.msg})") from None
        if not isinstance(data, dict):
            raise PlantError(f"{path}:1: the plant must be a JSON object")
        return cls.from_mapping(data, str(path))

    def to_mapping(self) -> dict[str, Any]:
        data = dataclasses.asdict(self)
        data.pop("notes")
        if self.home_switch is not None:
            data["home_switch"] = list(self.home_switch)
        return data

    def write_json(self, path: Path) -> None:
        """Write atomically (temporary file in the same folder, then rename)."""
        temporary = path.with_name(f".{path.name}.tmp")
        temporary.write_text(json.dumps(self.to_mapping(), indent=2) + "\n", encoding="utf-8")
        os.replace(temporary, path)


def _reachable_speed_rpm(torque_constant: float, dc_bus_voltage: float) -> int:
    """80 % of the no-load speed the bus voltage allows (back-EMF Kt·ω/1.5 ≤ Vdc/√3), rounded down to 500 rpm."""
    omega = 0.8 * dc_bus_voltage / math.sqrt(3.0) * 1.5 / torque_constant
    return max(500, int(omega * 60.0 / (2 * math.pi) // 500 * 500))


def _coerce(key: str, value: Any, annotation: object, source: str) -> Any:
    """Check a JSON value against the field's declared type (`dataclasses.Field.type`: a string here)."""
    text = str(annotation)
    if value is None and "None" in text:
        return None
    if text.startswith("tuple"):
        if isinstance(value, list) and len(value) == 2 and all(_is_number(v) for v in value):
            return (float(value[0]), float(value[1]))
        raise PlantError(f"{source}: {key!r} must be [low, high] in revolutions")
    if text.startswith("bool"):
        if isinstance(value, bool):
            return value
        raise PlantError(f"{source}: {key!r} must be true or false")
    if text.startswith("int"):
        if isinstance(value, int) and not isinstance(value, bool):
            return value
        raise PlantError(f"{source}: {key!r} must be an integer")
    if text.startswith("float"):
        if _is_number(value):
            return float(value)
        raise PlantError(f"{source}: {key!r} must be a number")
    if text.startswith("str"):
        if isinstance(value, str):
            return value
        raise PlantError(f"{source}: {key!r} must be a string")
    raise PlantError(f"{source}: {key!r} cannot be set")


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def _validate(plant: Plant) -> list[str]:
    problems: list[str] = []
    positive = (
        "torque_constant",
        "phase_resistance",
        "inductance",
        "motor_inertia",
        "peak_current",
        "stall_current",
        "dc_bus_voltage",
        "dc_bus_capacitance",
        "supply_resistance",
        "braking_resistance",
        "braking_on_voltage",
        "overvoltage",
        "thermal_resistance",
        "thermal_time_constant",
    )
    for name in positive:
        if not getattr(plant, name) > 0:
            problems.append(f"{name!r} must be > 0")
    for name in (
        "load_inertia",
        "viscous_friction",
        "coulomb_friction",
        "coupling_stiffness",
        "coupling_damping",
        "brake_torque",
    ):
        if getattr(plant, name) < 0:
            problems.append(f"{name!r} must be >= 0")
    if not 1 <= plant.pole_pairs <= 24:
        problems.append("'pole_pairs' must be 1..24")
    if plant.phase_order not in (PHASE_240, PHASE_120):
        problems.append("'phase_order' must be 0x5555 (21845) or 0xAAAA (43690)")
    if not 0 <= plant.sensor_offset <= 0xFFFF:
        problems.append("'sensor_offset' must be 0..65535")
    if plant.feedback not in (FEEDBACK_RESOLVER, FEEDBACK_ENCODER):
        problems.append("'feedback' must be 'resolver' or 'encoder'")
    if not 256 <= plant.encoder_counts <= 1 << 24:
        problems.append("'encoder_counts' must be 256..16777216")
    if plant.peak_current < plant.stall_current:
        problems.append("'peak_current' must be >= 'stall_current'")
    if plant.max_speed_rpm <= 0:
        problems.append("'max_speed_rpm' must be > 0")
    if plant.coupling_stiffness > 0:
        if plant.load_inertia <= 0:
            problems.append("a coupling needs 'load_inertia' > 0")
        else:
            reduced = plant.motor_inertia * plant.load_inertia / (plant.motor_inertia + plant.load_inertia)
            if math.sqrt(plant.coupling_stiffness / reduced) / (2 * math.pi) > 800.0:
                problems.append("the coupling resonance must stay below 800 Hz (control period 250 µs)")
    if plant.home_switch is not None and not plant.home_switch[0] < plant.home_switch[1]:
        problems.append("'home_switch' must be [low, high] with low < high")
    problems += _check_order(plant)
    return problems


def _check_order(plant: Plant) -> list[str]:
    """Hard stops outside the limit switches; the axis starts between the hard stops (maybe on a switch)."""
    problems = []
    low, high = plant.negative_hard_stop, plant.positive_hard_stop
    for name in ("negative_limit_switch", "positive_limit_switch", "initial_position"):
        value = getattr(plant, name)
        if value is None:
            continue
        if low is not None and not low < value:
            problems.append(f"{name!r} ({value}) must be above 'negative_hard_stop' ({low})")
        if high is not None and not value < high:
            problems.append(f"{name!r} ({value}) must be below 'positive_hard_stop' ({high})")
    if (
        plant.negative_limit_switch is not None
        and plant.positive_limit_switch is not None
        and not plant.negative_limit_switch < plant.positive_limit_switch
    ):
        problems.append("'negative_limit_switch' must be below 'positive_limit_switch'")
    return problems
