"""Revolutions and rpm in a drive's own position units, from the objects its profile names.

The quick test speaks rpm and revolutions to the user; the drive takes user units (XtrapulsPac: 4096 motor
increments = 0x6093,1 / 0x6093,2 user units, manual §3.2.2.7) or encoder increments (CD1-k: 0x608F,1 per
revolution).  Without either, a revolution is 4096 units (both drives' default). Speeds are position units per
second unless the profile gives the drive a speed unit of its own (encoTRive: rpm).
"""

from __future__ import annotations

import math

from servostudio.drive.access import Drive

DEFAULT_UNITS_PER_REVOLUTION = 4096.0
MOTOR_INCREMENTS = 4096.0  # XtrapulsPac: the position factor's numerator counts these per revolution


def units_per_revolution(drive: Drive) -> float:
    """How many of the drive's position units one motor revolution is (speeds are units per second)."""
    profile = drive.profile
    if profile.has("position_factor_numerator") and profile.has("position_factor_denominator"):
        numerator = float(drive.read("position_factor_numerator").raw)
        denominator = float(drive.read("position_factor_denominator").raw)
        if numerator > 0 and denominator > 0:
            return MOTOR_INCREMENTS * denominator / numerator
    if profile.has("encoder_increments"):
        increments = float(drive.read("encoder_increments").raw)
        if increments > 0:
            return increments
    return DEFAULT_UNITS_PER_REVOLUTION


def rpm_to_units(rpm: float, per_revolution: float) -> int:
    """A speed in rpm as position units per second (rounded)."""
    return round(rpm * per_revolution / 60.0)


def rpm_to_speed(drive: Drive, rpm: float) -> int:
    """A speed in rpm in the drive's own speed unit (rounded): the profile's (encoTRive: rpm, its factory velocity
    factor), else position units per second."""
    unit = drive.profile.speed_unit_rad_s
    if unit:
        return round(rpm * 2.0 * math.pi / 60.0 / unit)
    return rpm_to_units(rpm, units_per_revolution(drive))
