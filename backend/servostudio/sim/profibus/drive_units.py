"""Conversions between the TTA-PRO's units and the loops' motor units, read from its parameters each cycle.

Positions are increments of the position resolution (PNU 870, the double-word form of 740; 740 = 0 means 65536)
per motor revolution, reversed by PNU 722, shifted by the homing offset. Speeds are rpm; ramps are milliseconds
from standstill to the maximum speed PNU 721; currents are shares of the drive rating (PNU 715, 0x7FFF = rating).
"""

from __future__ import annotations

import math

from servostudio.sim.profibus.parameters import ParameterMemory

TWO_PI = 2.0 * math.pi
RPM = TWO_PI / 60.0
FULL_SCALE = 32767
RATINGS_230V = {1: 2.25, 2: 4.5, 3: 7.5, 4: 10.5, 5: 16.5, 6: 27.0, 7: 45.0, 8: 45.0, 9: 60.0, 10: 90.0, 11: 120.0}
"""PNU 715 bits 0-3 -> drive rating in A at 230 V (L1247-1276); the simulated drives are 230 V drives."""


def rating_code(peak_current: float) -> int:
    """The smallest 230 V rating that covers the motor's peak current."""
    return next((code for code, amps in RATINGS_230V.items() if amps >= peak_current), max(RATINGS_230V))


class DriveUnits:
    def __init__(self, memory: ParameterMemory) -> None:
        self.memory = memory
        self.offset = 0
        """Increments added to the measured position (set by homing)."""

    @property
    def increments_per_turn(self) -> int:
        return self.memory.get(870) or 65536

    @property
    def direction(self) -> int:
        return -1 if self.memory.get(722) else 1

    def position(self, rad: float) -> int:
        return round(self.direction * rad / TWO_PI * self.increments_per_turn) + self.offset

    def position_rad(self, increments: float) -> float:
        return (increments - self.offset) / self.increments_per_turn * TWO_PI * self.direction

    def distance_rad(self, increments: float) -> float:
        return increments / self.increments_per_turn * TWO_PI * self.direction

    @property
    def max_speed(self) -> float:
        """rad/s of PNU 721."""
        return self.memory.get(721) * RPM

    def speed_rad(self, rpm: float) -> float:
        return rpm * RPM

    def ramp(self, milliseconds: float) -> float:
        """rad/s² of a ramp from standstill to the maximum speed in `milliseconds`."""
        return self.max_speed / max(milliseconds, 0.5) * 1000.0

    @property
    def rating(self) -> float:
        return RATINGS_230V.get(self.memory.get(715) & 0x0F, 1.0)

    @property
    def max_current(self) -> float:
        """A of Imax (PNU 710, share of the rating)."""
        return self.memory.get(710) / FULL_SCALE * self.rating

    @property
    def rated_current(self) -> float:
        return self.memory.get(711) / FULL_SCALE * self.rating

    def share(self, value: float, full: float) -> int:
        """`value` as a signed share of `full` with 0x7FFF = full (monitors 776, 777)."""
        if full <= 0:
            return 0
        return max(-FULL_SCALE, min(FULL_SCALE, round(value / full * FULL_SCALE)))
