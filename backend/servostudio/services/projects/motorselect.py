"""Selecting a catalog motor for an axis: set the motor data and what the drive derives from it, in the project only.

Writing a 0x6410 sub-entry on an XtrapulsPac has documented side effects (manual L4894-5268); the project reproduces
them so that its values match what the drive will hold after the same writes:

- direct copies: motor type -> 0x6402, max speed -> 0x6080 (speed limit), inductance -> 0x340F, pole pairs / phase
  order / sensor offset -> 0x3410,1..3, induction-motor data -> 0x3420,1..5;
- current limits: stall and peak current "can modify" 0x6075 / 0x6073. The manual gives no formula; the project
  uses the rule of spec §6.8 that the simulated drive also applies (sim/drive/commissioning.py ``current_limits``):
  rated 0x6075 = min(stall, drive rated current 0x6510,2) mA, max 0x6073 = 1000 * min(peak, drive max current
  0x6510,1) / rated per mille, at most 32767; an unknown (0) drive current does not limit. The drive currents are
  read-only and have no dictionary default, so offline the limits come from the motor alone (reported in ``notes``).

The layout is per device: the CD1-k's 0x6410 holds other data, so only devices listed in ``LAYOUTS`` take catalog
motors.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from servostudio.od import Variable
from servostudio.services.projects.axisvalues import AxisValues
from servostudio.services.projects.errors import ParameterRefused
from servostudio.services.projects.motors import MOTOR_DATA_FIELDS, Motor

Key = tuple[int, int]
MAX_CURRENT_PER_MILLE = 32767


@dataclass(frozen=True)
class MotorDataLayout:
    """Where a device keeps the catalog's motor data and what it derives from it."""

    subs: Mapping[str, Key]  # motor-file field -> object
    copies: Mapping[str, Key]  # motor-file field -> object the drive copies the value into
    rated_current: Key
    max_current: Key
    drive_max_current: Key
    drive_rated_current: Key


XTRAPULSPAC_MOTOR_DATA = MotorDataLayout(
    subs={name: (0x6410, sub) for sub, name in enumerate(MOTOR_DATA_FIELDS, start=1)},
    copies={
        "motor_type": (0x6402, 0),
        "max_speed": (0x6080, 0),
        "inductance": (0x340F, 0),
        "pole_pairs": (0x3410, 1),
        "phase_order": (0x3410, 2),
        "sensor_offset": (0x3410, 3),
        "magnetization_current": (0x3420, 1),
        "rotor_time_constant": (0x3420, 2),
        "base_speed": (0x3420, 3),
        "leakage_factor": (0x3420, 4),
        "saturation_model": (0x3420, 5),
    },
    rated_current=(0x6075, 0),
    max_current=(0x6073, 0),
    drive_max_current=(0x6510, 1),
    drive_rated_current=(0x6510, 2),
)
LAYOUTS: dict[str, MotorDataLayout] = {"xtrapulspac": XTRAPULSPAC_MOTOR_DATA}


@dataclass(frozen=True)
class MotorApplication:
    changed: list[Variable]  # every object the selection set, in order
    notes: list[str]  # consequences not reproduced, or reproduced with missing inputs


def current_limits(stall: int, peak: int, drive_max: int, drive_rated: int) -> tuple[int, int]:
    """(rated current mA, max current per mille of it); (0, 0) when no rated current results."""
    rated = min((value for value in (stall, drive_rated) if value > 0), default=0)
    limit = min((value for value in (peak, drive_max) if value > 0), default=0)
    if rated <= 0:
        return 0, 0
    return rated, min(MAX_CURRENT_PER_MILLE, round(1000 * limit / rated))


def apply_motor(values: AxisValues, motor: Motor) -> MotorApplication:
    """Stage the motor's values and their consequences; a refused motor value raises :class:`ParameterRefused`
    (the caller then writes nothing)."""
    device = values.dictionary.device
    layout = LAYOUTS.get(device)
    if layout is None:
        raise ParameterRefused(
            f"device '{device}' does not take catalog motors (the catalog uses the XtrapulsPac "
            "0x6410 motor data layout)"
        )
    changed: list[Variable] = []
    notes: list[str] = []
    for name, value in motor.motor_data.items():
        changed.append(_stage(values, layout.subs[name], value, motor))
        if name in layout.copies:
            _consequence(values, layout.copies[name], value, changed, notes)
    for key, setting in sorted(motor.objects.items()):
        changed.append(_stage(values, key, setting, motor))
    _current_limits(values, layout, motor, changed, notes)
    return MotorApplication(changed, notes)


def _stage(values: AxisValues, key: Key, value: object, motor: Motor) -> Variable:
    variable = values.dictionary.get(*key)
    if variable is None:
        raise ParameterRefused(
            f"motor '{motor.reference}' sets 0x{key[0]:04X},{key[1]}, which device "
            f"'{values.dictionary.device}' does not have"
        )
    values.stage(variable, value)
    return variable


def _consequence(values: AxisValues, key: Key, value: object, changed: list[Variable], notes: list[str]) -> None:
    target = values.dictionary.get(*key)
    if target is None:
        notes.append(f"not set: 0x{key[0]:04X},{key[1]} is not in the dictionary")
        return
    reason = values.editable_reason(target)
    if reason:
        notes.append(f"not set: {reason}")
        return
    try:
        values.stage(target, value)
    except ParameterRefused as refusal:
        notes.append(f"not set: {refusal}")
        return
    changed.append(target)


def _current_limits(
    values: AxisValues, layout: MotorDataLayout, motor: Motor, changed: list[Variable], notes: list[str]
) -> None:
    stall = motor.motor_data.get("stall_current")
    peak = motor.motor_data.get("peak_current")
    if not isinstance(stall, int) and not isinstance(peak, int):
        return
    drive = []
    for key in (layout.drive_max_current, layout.drive_rated_current):
        variable = values.dictionary.get(*key)
        current = values.value(variable) if variable is not None else None
        drive.append(current if isinstance(current, int) else 0)
    if 0 in drive:
        notes.append(
            "current limits derived from the motor data alone: the drive's current ratings 0x6510,1/2 are "
            "unknown offline and the drive caps the limits to them"
        )
    rated, maximum = current_limits(
        stall if isinstance(stall, int) else 0, peak if isinstance(peak, int) else 0, *drive
    )
    if rated:
        _consequence(values, layout.rated_current, rated, changed, notes)
        _consequence(values, layout.max_current, maximum, changed, notes)
