"""User position units and motor revolutions: what one revolution is for this drive (its profile's ``UserUnits``),
so a speed step or a standstill threshold can be given in rpm or rad/s whatever the factor group says."""

from __future__ import annotations

import math

from servostudio.drive.access import Drive

TWO_PI = 2.0 * math.pi


def units_per_revolution(drive: Drive) -> float:
    """User position units of one motor revolution (XtrapulsPac: 4096 × 0x6093,2 / 0x6093,1; CD1-k: 0x608F,1)."""
    units = drive.profile.procedures.units
    increments = units.increments if isinstance(units.increments, int) else _value(drive, units.increments, 0.0)
    numerator = _value(drive, units.numerator, 1.0) if units.numerator else 1.0
    denominator = _value(drive, units.denominator, 1.0) if units.denominator else 1.0
    if increments <= 0 or numerator <= 0 or denominator <= 0:
        return 4096.0
    return float(increments) * denominator / numerator


def speed_rad_s(drive: Drive, user_per_s: float) -> float:
    """rad/s of a speed in the drive's speed unit (the profile's own, e.g. the encoTRive's rpm, else units/s)."""
    unit = drive.profile.speed_unit_rad_s
    return user_per_s * unit if unit else user_per_s / units_per_revolution(drive) * TWO_PI


def user_speed(drive: Drive, rad_s: float) -> float:
    unit = drive.profile.speed_unit_rad_s
    return rad_s / unit if unit else rad_s / TWO_PI * units_per_revolution(drive)


def _value(drive: Drive, name: str, default: float) -> float:
    if (
        not drive.profile.has(name)
        or drive.dictionary is None
        or drive.dictionary.get(*drive.profile.address(name)) is None
    ):
        return default
    return float(drive.read(name).raw)
