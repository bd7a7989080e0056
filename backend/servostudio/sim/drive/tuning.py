"""Auto-tuning ('atun', 0x3426): identify the mechanics, then compute the gains (docs/control-loops.md §4).

Two stages, both run by the drive from its own sensor and current:

1. **Coarse inertia** from current pulses `+I, coast, −I, coast` of length T (T doubles from 2 ms until the
   speed reached is worth measuring). The speed at the end of a pulse and the friction deceleration come from a
   quadratic fit of the position during the coast, so J0 = Kt·I·T / (ω_end − a·T) does not mistake friction
   for inertia, and the coast averages a two-mass load's ringing.
2. **Speed plateaus** under a soft speed loop built from J0 (PI + acceleration feed-forward): four passes
   (+, −, −, +, so the axis ends where it started), each `0 → ω1 → 3·ω1 → ω1 → 0` with smooth ramps. The fit
   uses whole intervals that never cross zero speed, with the speed at each end averaged over 10 ms:

       Kt·∫iq dt = J·(ω_b − ω_a) + B·(x_b − x_a) + Tc·s·Δt + Tg·Δt            (s = direction of the pass)

   on each plateau (B and Tc separate because there are two speed levels; Tc and Tg because there are two
   directions) and from plateau centre to plateau centre across each ramp (J). Least squares on the mean-torque
   form of these rows gives J, B, Tc and Tg; the residual (RMS fit error / RMS torque) is the quality figure.
   If J differs much from J0 the plateau stage runs once more with the better loop.

Kt is the drive's torque constant (0x6410,11 on the XtrapulsPac). A drive without one (the CD1-k) identifies
with Kt = 1: its results are then per N·m/A (A·s²/rad, A·s/rad, A, A), which is all its gains need.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

TWO_PI = 2.0 * math.pi

START_PULSE = 0.002
MAX_PULSE = 0.064
COAST = 0.025
WANTED_SPEED = 10.0
"""rad/s at the end of a pulse for the coarse inertia."""
TRAVEL = 3.8
"""rad: the excursion of one plateau pass (the axis swings ±TRAVEL about its start)."""
HOLD = 0.06
"""s: plateau length on a rigid axis (or one resonating far above the soft loop)."""
RAMP_MIN = 0.04
AVERAGE = 0.01
"""s: half-width of the position window that gives a speed at a row's end."""
LOOP_HZ = 15.0
SOFT_SHARE = 1.0 / 8.0
"""With a coupling resonance f_r seen in the coast, the soft loop stays below f_r·SOFT_SHARE, each plateau lasts
HOLD_PERIODS resonance periods and the end speeds average one period: a low resonance (60–100 Hz, its
anti-resonance near the soft loop) otherwise leaves motor and load swinging against each other at the plateau ends,
and the motor's speed alone then misstates the momentum (measured on seed 15: viscous friction 3.5 × the truth)."""
HOLD_PERIODS = 6.0
ACCELERATION_SHARE = 0.3
"""Peak acceleration torque of the plateau ramps as a share of Kt·I (room for friction and the loop)."""
REST = 0.03
SETTLE = 4
"""Coast samples skipped before looking for ringing (the current takes about a millisecond to fall)."""
RINGING_LOW_HZ = 40.0
RINGING_HIGH_HZ = 1000.0
RINGING_MIN_RAD = 2e-4


@dataclass(frozen=True)
class Identified:
    inertia: float
    viscous_friction: float
    coulomb_friction: float
    load_torque: float
    """Constant torque opposing positive motion (the plant's gravity torque); 0x3428,4 publishes −load_torque."""
    torque_constant: float
    residual: float = 0.0
    resonance_hz: float = 0.0


class AutoTuning:
    """Drive it with `step(position, speed, current)` each period; read `current_demand` for the q current."""

    def __init__(self, dt: float, current: float, torque_constant: float, bias: float = 0.0) -> None:
        self.dt = dt
        self.current = current
        self.torque_constant = torque_constant
        self.bias = bias
        """q current that held the axis at standstill when tuning started enabled (a vertical load): every stage
        adds it, so the load does not fall while the axis coasts."""
        self.swing = current - abs(bias)
        """Current available above the holding current: the pulses' height and the plateaus' acceleration budget."""
        self.current_demand = 0.0
        self.result: Identified | None = None
        self.failed_reason = ""
        self.resonance_hz = 0.0
        """The coupling resonance seen while coasting after the first pulse (0 = none: a rigid load)."""
        self._stage: _Stage = _PulseStage(self)

    def step(self, position: float, speed: float, current: float) -> bool:
        """One period with the sensor position (rad), filtered speed (rad/s) and q current (A); True when done."""
        if self.torque_constant <= 0.0:
            self.failed_reason = "torque constant 0x6410,11 is 0"
            return True
        if self.current <= 0.0:
            self.failed_reason = "no current available (rated/max current 0x6075/0x6073 is 0)"
            return True
        if self.swing <= 0.1 * self.current:
            self.failed_reason = "the load torque takes all the current (holding current close to the limit)"
            return True
        demand, following = self._stage.step(position, speed, current)
        self.current_demand = max(-self.current, min(self.current, demand))
        if following is None:
            return False
        if isinstance(following, _Stage):
            self._stage = following
            return False
        return True


class _Stage:
    def __init__(self, tuning: AutoTuning) -> None:
        self.tuning = tuning
        self.positions: list[float] = []
        self.currents: list[float] = []

    def step(self, position: float, speed: float, current: float) -> tuple[float, _Stage | bool | None]:
        raise NotImplementedError

    def _fail(self, reason: str) -> tuple[float, bool]:
        self.tuning.failed_reason = reason
        return 0.0, True


class _PulseStage(_Stage):
    """Stage 1: the coarse inertia J0 (and the friction torque seen while coasting)."""

    def __init__(self, tuning: AutoTuning, pulse: float = START_PULSE) -> None:
        super().__init__(tuning)
        self.pulse = pulse
        self.time = 0.0

    def step(self, position: float, speed: float, current: float) -> tuple[float, _Stage | bool | None]:
        self.positions.append(position)
        self.time += self.tuning.dt
        pulse, t = self.pulse, self.time
        cycle = pulse + COAST
        bias, swing = self.tuning.bias, self.tuning.swing
        if t < 2 * cycle + REST:
            if t < pulse:
                return bias + swing, None
            if cycle <= t < cycle + pulse:
                return bias - swing, None
            return bias, None
        estimate = self._estimate()
        if estimate is not None and estimate[0] > 0.0:
            return bias, _PlateauStage(self.tuning, *estimate)
        if pulse * 2 > MAX_PULSE:
            return self._fail("the axis did not move as a free inertia (blocked, brake engaged?)")
        return bias, _PulseStage(self.tuning, pulse * 2)

    def _estimate(self) -> tuple[float, float] | None:
        """(J0, friction torque) from the first pulse (from rest), or None if the coast was too short or slow.

        The second pulse only brings the axis back towards its start."""
        dt = self.tuning.dt
        end = round(self.pulse / dt)
        coast = self.positions[end : end + round(COAST / dt)]
        moving = _moving_prefix(coast)
        if len(moving) < 12:
            return None
        velocity, acceleration, residuals = _quadratic_fit(moving, dt)
        if velocity < WANTED_SPEED:
            return None
        torque = self.tuning.torque_constant * self.tuning.swing
        inertia = torque * self.pulse / (velocity - acceleration * self.pulse)
        self.tuning.resonance_hz = _ringing_hz(residuals[SETTLE:], dt)
        return inertia, -inertia * acceleration


def _moving_prefix(positions: list[float]) -> list[float]:
    """The coast samples up to where the axis stuck (no count change for 4 periods)."""
    for n in range(4, len(positions)):
        if positions[n] == positions[n - 4]:
            return positions[: n - 4]
    return positions


def _quadratic_fit(positions: list[float], dt: float) -> tuple[float, float, list[float]]:
    """Speed at the first sample and the (constant) acceleration of x(t) = x0 + v·t + a·t²/2, and the residuals."""
    rows = [([1.0, n * dt, 0.5 * (n * dt) ** 2], x - positions[0]) for n, x in enumerate(positions)]
    solution = _least_squares(rows, 3) or [0.0, 0.0, 0.0]
    residuals = [y - sum(a * b for a, b in zip(x, solution, strict=True)) for x, y in rows]
    return solution[1], solution[2], residuals


def _ringing_hz(residuals: list[float], dt: float) -> float:
    """Frequency of the coast's ringing (a two-mass load swinging on its coupling), 0 when there is none.

    A Hann-windowed spectrum of the position residual (less a cubic trend), scanned in 2 Hz steps; the peak counts
    if its amplitude is at least RINGING_MIN_RAD and 4 × the median of the scan (the sensor's quantisation gives a
    flat floor) and it lies inside the scan."""
    count = len(residuals)
    if count < 24:
        return 0.0
    original = residuals
    cubic = _least_squares([([1.0, n, n * n, n * n * n], r) for n, r in enumerate(residuals)], 4) or [0.0] * 4
    residuals = [r - sum(c * n**k for k, c in enumerate(cubic)) for n, r in enumerate(residuals)]
    window = [0.5 - 0.5 * math.cos(TWO_PI * n / (count - 1)) for n in range(count)]
    weighted = [r * w for r, w in zip(residuals, window, strict=True)]
    scale = 2.0 / sum(window)
    spectrum = []
    frequency = RINGING_LOW_HZ
    while frequency <= min(RINGING_HIGH_HZ, 0.4 / dt):
        turn = TWO_PI * frequency * dt
        real = sum(v * math.cos(turn * n) for n, v in enumerate(weighted))
        imaginary = sum(v * math.sin(turn * n) for n, v in enumerate(weighted))
        spectrum.append((scale * math.hypot(real, imaginary), frequency))
        frequency += 2.0
    amplitude, peak = max(spectrum)
    floor = sorted(a for a, _ in spectrum)[len(spectrum) // 2]
    inside = spectrum[0][1] < peak < spectrum[-1][1]  # a peak at the scan's edge is the fit's leftover trend
    found = inside and amplitude >= RINGING_MIN_RAD and amplitude >= 4.0 * floor
    return _refined_hz(original, peak, dt) if found else 0.0


def _refined_hz(residuals: list[float], peak: float, dt: float) -> float:
    """The ringing's frequency to 1 Hz: the spectrum of a coast that holds only one or two periods of a low
    resonance (and less its cubic trend) peaks well above it (82 Hz for 63 Hz); a least-squares sine plus quadratic
    trend, scanned from half to 1.2 × that peak, is unbiased on so short a record. A best fit at the scan's edge
    means the residual is no ringing (a rigid axis coasting under gravity): 0."""

    def misfit(frequency: float) -> float:
        turn = TWO_PI * frequency * dt
        rows = [([1.0, n, n * n, math.cos(turn * n), math.sin(turn * n)], r) for n, r in enumerate(residuals)]
        solution = _least_squares(rows, 5)
        if solution is None:
            return math.inf
        return sum((y - sum(a * b for a, b in zip(x, solution, strict=True))) ** 2 for x, y in rows)

    scan = range(int(max(RINGING_LOW_HZ, round(0.5 * peak))), int(1.2 * peak) + 1)
    best = min(scan, key=misfit, default=scan.start)
    return 0.0 if best in (scan.start, scan.stop - 1) else float(best)  # at an edge: no sine there, not a resonance


class _PlateauStage(_Stage):
    """Stage 2: four passes of speed plateaus under a soft speed loop; then the least-squares fit."""

    PASSES = (1, -1, -1, 1)

    def __init__(self, tuning: AutoTuning, inertia: float, friction: float, model: list[float] | None = None) -> None:
        super().__init__(tuning)
        self.inertia = inertia
        self.friction = friction
        self.model = model
        """J, B, Tc, Tg of the first run: the second run feeds them forward, so its plateaus are steady."""
        kt = tuning.torque_constant
        self.hold, self.average, loop_hz = _timing(tuning.resonance_hz)
        omega = 2.0 * math.pi * loop_hz
        self.kp = inertia * omega / kt
        self.ki = self.kp * omega / 4.0
        self.integral = 0.0
        self.ramp, self.low = _plan(inertia, kt * tuning.swing, self.hold)
        self.segments = _profile(self.ramp, self.low, self.hold)
        self.pass_time = sum(length for length, _, _ in self.segments)
        self.period = 0
        self.directions: list[int] = []

    def step(self, position: float, speed: float, current: float) -> tuple[float, _Stage | bool | None]:
        tuning = self.tuning
        self.positions.append(position)
        self.currents.append(current)
        t = self.period * tuning.dt
        self.period += 1
        index = int(t // self.pass_time)
        if index >= len(self.PASSES):
            return 0.0, self._finish()
        direction = self.PASSES[index]
        self.directions.append(direction)
        reference, acceleration = _reference(self.segments, t - index * self.pass_time)
        error = direction * reference - speed
        self.integral += error * tuning.dt
        return self.kp * error + self.ki * self.integral + self._feed_forward(direction, reference, acceleration), None

    def _feed_forward(self, direction: int, speed: float, acceleration: float) -> float:
        """Current for the profile from the model known so far (J0, the coast friction and the holding current;
        then the first fit, whose constant load torque also holds the axis at rest)."""
        moving = 1.0 if speed > 0.0 else 0.0
        if self.model is None:
            torque = direction * (self.inertia * acceleration + self.friction * moving)
            return torque / self.tuning.torque_constant + self.tuning.bias
        inertia, viscous, coulomb, load = self.model
        torque = direction * (inertia * acceleration + viscous * speed + coulomb * moving) + load
        return torque / self.tuning.torque_constant

    def _finish(self) -> bool | _Stage:
        tuning = self.tuning
        rows = self._rows()
        solution = _least_squares([(x, y) for x, y in rows], 4)
        if solution is None or solution[0] <= 0.0:
            tuning.failed_reason = "the axis did not move as a free inertia (blocked, brake engaged?)"
            return True
        inertia, viscous, coulomb, load = solution
        if self.model is None:
            return _PlateauStage(tuning, inertia, coulomb, solution)
        residual = _residual(rows, solution)
        tuning.result = Identified(
            inertia, max(viscous, 0.0), max(coulomb, 0.0), load, tuning.torque_constant, residual, tuning.resonance_hz
        )
        return True

    def _rows(self) -> list[tuple[list[float], float]]:
        """Mean-torque rows: [Δω/Δt, Δx/Δt, s, 1] → Kt·mean(iq) over plateaus and plateau-to-plateau intervals."""
        dt = self.tuning.dt
        rows = []
        for index, direction in enumerate(self.PASSES):
            base = index * self.pass_time
            holds = _hold_windows(self.segments, base)
            for start, end in holds:
                rows.append(self._row(start + self.average, end - self.average, direction, dt))
            for (a, b), (c, d) in itertools.pairwise(holds):
                rows.append(self._row((a + b) / 2, (c + d) / 2, direction, dt))
        return rows

    def _row(self, start: float, end: float, direction: int, dt: float) -> tuple[list[float], float]:
        a, b = round(start / dt), round(end / dt)
        span = (b - a) * dt
        torque = self.tuning.torque_constant * sum(self.currents[a + 1 : b + 1]) / (b - a)
        acceleration = (self._speed(b) - self._speed(a)) / span
        speed = (self.positions[b] - self.positions[a]) / span
        return [acceleration, speed, float(direction), 1.0], torque

    def _speed(self, n: int) -> float:
        """Speed at period n: slope of a cubic fitted to the positions within ±average (unbiased by a changing
        acceleration, and the fit averages the sensor's quantisation)."""
        dt = self.tuning.dt
        width = round(self.average / dt)
        centre = self.positions[n]
        rows = [
            ([1.0, k * dt, (k * dt) ** 2, (k * dt) ** 3], self.positions[n + k] - centre)
            for k in range(-width, width + 1)
        ]
        solution = _least_squares(rows, 4)
        return solution[1] if solution else 0.0


def _timing(resonance_hz: float) -> tuple[float, float, float]:
    """Plateau length, end-speed half-window (s) and soft-loop frequency (Hz) for the resonance seen (0 = none)."""
    if resonance_hz <= 0.0:
        return HOLD, AVERAGE, LOOP_HZ
    return (
        max(HOLD, HOLD_PERIODS / resonance_hz),
        max(AVERAGE, 1.0 / resonance_hz),
        min(LOOP_HZ, SOFT_SHARE * resonance_hz),
    )


def _plan(inertia: float, torque: float, hold: float) -> tuple[float, float]:
    """Ramp time and low plateau speed: the pass travels TRAVEL, the ramps stay within ACCELERATION_SHARE."""
    # travel = ω1·(5·ramp + 5·hold); peak acceleration of a cycloidal ramp of 2·ω1 = 4·ω1/ramp
    limit = ACCELERATION_SHARE * torque / inertia
    # ramp·(ramp + hold) ≥ 4·TRAVEL / (5·limit)
    need = 4.0 * TRAVEL / (5.0 * limit)
    ramp = max(RAMP_MIN, (-hold + math.sqrt(hold * hold + 4.0 * need)) / 2.0)
    return ramp, TRAVEL / (5.0 * (ramp + hold))


def _profile(ramp: float, low: float, hold: float) -> list[tuple[float, float, float]]:
    """Segments (length, start speed, end speed) of one pass: 0 → ω1 → 3ω1 → ω1 → 0, with holds and a rest."""
    high = 3.0 * low
    levels = [(ramp, 0.0, low), (hold, low, low), (ramp, low, high), (hold, high, high)]
    levels += [(ramp, high, low), (hold, low, low), (ramp, low, 0.0), (REST, 0.0, 0.0)]
    return levels


def _reference(segments: list[tuple[float, float, float]], t: float) -> tuple[float, float]:
    """Speed and acceleration of the profile at `t`: cycloidal ramps, whose acceleration 1 − cos starts and ends
    at zero, so they hardly excite a two-mass load's resonance."""
    for length, start, end in segments:
        if t < length:
            phase = TWO_PI * t / length
            shape = t / length - math.sin(phase) / TWO_PI
            slope = (1.0 - math.cos(phase)) / length
            return start + (end - start) * shape, (end - start) * slope
        t -= length
    return 0.0, 0.0


def _hold_windows(segments: list[tuple[float, float, float]], base: float) -> list[tuple[float, float]]:
    windows = []
    t = base
    for length, start, end in segments:
        if start == end and start > 0.0:
            windows.append((t, t + length))
        t += length
    return windows


def _residual(rows: list[tuple[list[float], float]], solution: list[float]) -> float:
    errors = [y - sum(a * b for a, b in zip(x, solution, strict=True)) for x, y in rows]
    scale = math.sqrt(sum(y * y for _, y in rows) / len(rows)) or 1.0
    return min(1.0, math.sqrt(sum(e * e for e in errors) / len(errors)) / scale)


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
        if abs(matrix[pivot][column]) < 1e-30:
            return None
        matrix[column], matrix[pivot] = matrix[pivot], matrix[column]
        for r in range(size):
            if r != column:
                factor = matrix[r][column] / matrix[column][column]
                for c in range(column, size + 1):
                    matrix[r][c] -= factor * matrix[column][c]
    return [matrix[r][size] / matrix[r][r] for r in range(size)]
