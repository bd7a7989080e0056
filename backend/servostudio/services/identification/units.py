"""The experiment's quantities in SI units, from the objects the drive's profile names: shaft angle per position
unit, rad/s per speed unit (the profile's own speed unit, e.g. the encoTRive's rpm, else position units per second)
and N·m per ‰ of the measured current 0x6078 (of the rated current 0x6075)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from servostudio.drive.access import Drive
from servostudio.services.identification.estimator import IdentificationFailed
from servostudio.services.motion.units import units_per_revolution

TWO_PI = 2.0 * math.pi


@dataclass(frozen=True)
class Scales:
    rad_per_unit: float
    rad_s_per_speed_unit: float
    rad_s2_per_acceleration_unit: float
    nm_per_permille: float
    #: N·m of the rated current (the current limit's 100 %)
    rated_torque_nm: float


def scales(drive: Drive) -> Scales:
    """The drive's scales, read now; a drive whose current cannot be turned into torque cannot be identified."""
    profile = drive.profile
    rad = TWO_PI / units_per_revolution(drive)
    torque = rated_torque_nm(drive)
    return Scales(rad, profile.speed_unit_rad_s or rad, profile.acceleration_unit_rad_s2 or rad, torque / 1000, torque)


def rated_torque_nm(drive: Drive) -> float:
    """The torque of the rated current: 0x6076 (mN·m) where the drive has it, else 0x6075 (mA) × the motor's torque
    constant (XtrapulsPac 0x6410,11, mN·m/A)."""
    if _positive(drive, "rated_torque"):
        return float(drive.read("rated_torque").raw) / 1000
    constant = drive.profile.procedures.torque_constant
    if _positive(drive, "rated_current") and constant is not None and _positive(drive, constant):
        return float(drive.read("rated_current").raw) / 1000 * float(drive.read(constant).raw) / 1000
    raise IdentificationFailed(
        f"node {drive.node}: the {drive.profile.device} gives no motor rated torque (0x6076) nor rated current and "
        "torque constant: the measured current cannot be turned into torque"
    )


def _positive(drive: Drive, name: str) -> bool:
    if not drive.profile.has(name) or drive.dictionary is None:
        return False
    if drive.dictionary.get(*drive.profile.address(name)) is None:
        return False
    return float(drive.read(name).raw) > 0
