"""Conversions between a device's bus units and the motor units the loops use (rad, rad/s, rad/s²).

XtrapulsPac factor group (manual §3.2.2.7): motor increments (4096 per revolution) = 0x6093,1 / 0x6093,2 × user
units, so one motor revolution is 4096·den/num user units; speeds are user units/s, accelerations user
units/s². A device may give speeds and accelerations their own scale (encoTRive: rpm and rpm/s).
"""

from __future__ import annotations

import math

TWO_PI = 2.0 * math.pi
RPM = TWO_PI / 60.0


class UnitScaling:
    def __init__(
        self,
        user_per_revolution: float = 4096.0,
        speed_unit_rad: float | None = None,
        accel_unit_rad: float | None = None,
    ) -> None:
        self.user_per_revolution = user_per_revolution
        self._position_unit = TWO_PI / user_per_revolution
        self._speed_unit = speed_unit_rad if speed_unit_rad is not None else self._position_unit
        self._accel_unit = accel_unit_rad if accel_unit_rad is not None else self._position_unit

    @classmethod
    def from_position_factor(cls, numerator: int, denominator: int) -> UnitScaling:
        if numerator <= 0 or denominator <= 0:
            return cls()
        return cls(4096.0 * denominator / numerator)

    def to_rad(self, user: float) -> float:
        return user * self._position_unit

    def to_user(self, rad: float) -> float:
        return rad / self._position_unit

    def speed_to_rad(self, user: float) -> float:
        return user * self._speed_unit

    def speed_to_user(self, rad_s: float) -> float:
        return rad_s / self._speed_unit

    def accel_to_rad(self, user: float) -> float:
        return user * self._accel_unit
