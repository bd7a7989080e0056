"""I²t protection of the motor current (manual §3.2.1.5 and §2.4.11; model of spec §6.3).

    E += (i² − Ir²)·dt, E ≥ 0;  E_lim = 4 s·Ir² below 2 Hz current frequency (locked shaft), 12 s·Ir² above
    warning at E ≥ 0.85·E_lim, current limited to Ir at E ≥ E_lim;
    Fusing mode (0x3404,1 = 1): error 38 when the limitation has lasted 1 s (t3 = t2 + 1 s in the manual's diagram).

For i = Imax this gives t_limit ≈ 4·r² s (locked) with r = Ir/Imax, as the manual's table. The I²t signal
0x3404,2 is 32768·Irms²/Iamp² with Irms² a 4 s average of i² (32768 ⇔ RMS current = drive rating 0x6510,1).
"""

from __future__ import annotations

import math

LOCKED_SECONDS = 4.0
RUNNING_SECONDS = 12.0
WARNING_FRACTION = 0.85
FUSING_DELAY = 1.0
SIGNAL_TIME_CONSTANT = 4.0
LOCKED_FREQUENCY_HZ = 2.0


class I2tProtection:
    def __init__(self, dt: float) -> None:
        self.dt = dt
        self.energy = 0.0
        self.mean_square = 0.0
        self.warning = False
        self.limiting = False
        self.limiting_time = 0.0
        self._signal_alpha = 1.0 - math.exp(-dt / SIGNAL_TIME_CONSTANT)

    def step(self, current: float, rated: float, electrical_hz: float) -> bool:
        """Integrate one period; True when the Fusing error is due (caller checks the mode)."""
        square = current * current
        rated_square = rated * rated
        self.energy = max(0.0, self.energy + (square - rated_square) * self.dt)
        seconds = LOCKED_SECONDS if abs(electrical_hz) < LOCKED_FREQUENCY_HZ else RUNNING_SECONDS
        limit = seconds * rated_square
        self.warning = self.energy >= WARNING_FRACTION * limit
        self.limiting = self.energy >= limit and limit > 0.0
        self.limiting_time = self.limiting_time + self.dt if self.limiting else 0.0
        self.mean_square += self._signal_alpha * (square - self.mean_square)
        return self.limiting_time >= FUSING_DELAY

    def signal(self, amplifier_rating: float) -> int:
        if amplifier_rating <= 0.0:
            return 0
        return min(0xFFFF, round(32768.0 * self.mean_square / (amplifier_rating * amplifier_rating)))

    def reset(self) -> None:
        self.energy = 0.0
        self.limiting_time = 0.0
        self.warning = self.limiting = False
