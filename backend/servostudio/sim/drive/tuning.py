"""Auto-tuning ('atun', 0x3426): identify the mechanics with current pulses, then compute the gains.

Excitation: symmetric current pulses +I for T, −I for 2T, +I for T (the axis returns near its start), with T
doubling from 5 ms until the speed reached makes the identification well conditioned (≥ 20 rad/s) or the
travel nears half a revolution. Identification: least squares on windows of 8 periods of

    J·Δω + Tc·∫sign(ω)dt + B·∫ω dt + Tg·Δt = Kt·∫iq dt

with Kt the motor data 0x6410,11 (the gains are consistent with what the drive believes about Kt). The gains
follow `gains.tuned_gains` (docs/control-loops.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

START_PULSE = 0.005
MAX_PULSE = 0.32
WANTED_SPEED = 20.0
MAX_TRAVEL = math.pi
REST_TIME = 0.1
WINDOW = 8


@dataclass(frozen=True)
class Identified:
    inertia: float
    viscous_friction: float
    coulomb_friction: float
    load_torque: float
    torque_constant: float


class AutoTuning:
    def __init__(self, dt: float, current: float, torque_constant: float) -> None:
        self.dt = dt
        self.current = current
        self.torque_constant = torque_constant
        self.current_demand = 0.0
        self.result: Identified | None = None
        self.failed_reason = ""
        self._pulse = START_PULSE
        self._time = 0.0
        self._travel = 0.0
        self._peak_speed = 0.0
        self._peak_travel = 0.0
        self._samples: list[tuple[float, float]] = []

    def step(self, speed: float, current: float) -> bool:
        """One period with the measured speed (rad/s) and q current (A); True when finished."""
        if self.torque_constant <= 0.0:
            self.failed_reason = "torque constant 0x6410,11 is 0"
            return True
        self._samples.append((speed, current))
        self._travel += speed * self.dt
        self._peak_speed = max(self._peak_speed, abs(speed))
        self._peak_travel = max(self._peak_travel, abs(self._travel))
        self._time += self.dt
        pulse = self._pulse
        if self._time < pulse or 3 * pulse <= self._time < 4 * pulse:
            self.current_demand = self.current
        elif self._time < 3 * pulse:
            self.current_demand = -self.current
        else:
            self.current_demand = 0.0
        if self._time < 4 * pulse + REST_TIME:
            return False
        good = self._peak_speed >= WANTED_SPEED or self._peak_travel >= MAX_TRAVEL / 2
        if good or pulse * 2 > MAX_PULSE:
            return self._identify()
        self._pulse = pulse * 2
        self._time = 0.0
        self._samples.clear()
        self._peak_speed = self._peak_travel = 0.0
        return False

    def _identify(self) -> bool:
        rows: list[tuple[list[float], float]] = []
        samples = self._samples
        dt = self.dt
        for start in range(0, len(samples) - WINDOW, WINDOW):
            chunk = samples[start : start + WINDOW + 1]
            delta = chunk[-1][0] - chunk[0][0]
            signs = sum(math.copysign(1.0, s) if abs(s) > 0.5 else 0.0 for s, _ in chunk[:-1]) * dt
            integral = sum(s for s, _ in chunk[:-1]) * dt
            torque = self.torque_constant * sum(i for _, i in chunk[:-1]) * dt
            rows.append(([delta, signs, integral, WINDOW * dt], torque))
        solution = _least_squares(rows, 4)
        if solution is None or solution[0] <= 0.0:
            self.failed_reason = "the axis did not move as a free inertia (blocked, brake engaged?)"
            return True
        inertia, coulomb, viscous, load = solution
        self.result = Identified(inertia, max(viscous, 0.0), max(coulomb, 0.0), load, self.torque_constant)
        return True


def _least_squares(rows: list[tuple[list[float], float]], size: int) -> list[float] | None:
    """Normal equations solved by Gaussian elimination with partial pivoting (pure Python, small systems)."""
    if len(rows) < size:
        return None
    matrix = [[0.0] * (size + 1) for _ in range(size)]
    for x, y in rows:
        for r in range(size):
            for c in range(size):
                matrix[r][c] += x[r] * x[c]
            matrix[r][size] += x[r] * y
    for column in range(size):
        pivot = max(range(column, size), key=lambda r: abs(matrix[r][column]))
        if abs(matrix[pivot][column]) < 1e-18:
            return None
        matrix[column], matrix[pivot] = matrix[pivot], matrix[column]
        for r in range(size):
            if r != column:
                factor = matrix[r][column] / matrix[column][column]
                for c in range(column, size + 1):
                    matrix[r][c] -= factor * matrix[column][c]
    return [matrix[r][size] / matrix[r][r] for r in range(size)]
