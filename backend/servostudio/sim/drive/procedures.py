"""Procedures started by writing a 4-character signature (decisions.md §4) and the drive-side algorithms.

Status read back from the trigger object: 0 never executed, 1 cannot execute, 2 running, 3 aborted, 4 stopped on
error, 5 done. Status word bit 15 is set while one runs; a failure raises error 64 "procedure error".

Auto-phasing ('apha') identifies pole pairs, phase order and sensor offset from the motor itself: it injects a
d-axis current vector at a forced electrical angle, turns that angle slowly forward until the sensor has seen
one mechanical revolution (pole pairs = electrical turns / mechanical turns, the sign gives the phase order),
turns it back, and takes the offset as the circular mean of S·φ/2π − pp·turns over both sweeps (forward and
backward lag from friction cancel). Motor phasing ('mcal') finds only the offset with pole pairs and phase
order already known, with a ±1 electrical turn sweep.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from servostudio.sim.drive.physics import TWO_PI

NEVER_EXECUTED = 0
CANNOT_EXECUTE = 1
RUNNING = 2
ABORTED = 3
FAILED = 4
DONE = 5


def signature(text: str) -> int:
    """'apha' → 0x61687061: four ASCII characters as a little-endian U32."""
    return int.from_bytes(text.encode("ascii"), "little")


class ProcedureSlot:
    """Status of one trigger object."""

    def __init__(self, name: str) -> None:
        self.name = name
        self.status = NEVER_EXECUTED

    @property
    def running(self) -> bool:
        return self.status == RUNNING


@dataclass
class PhasingResult:
    pole_pairs: int
    phase_sign: int
    offset: int  # 0x3410,3: 65536 = one electrical turn


class ForcedVectorSweep:
    """Common machinery: align, then sweep the forced angle and sample (angle, sensor turns, direction)."""

    ALIGN_TIME = 0.6
    ELECTRICAL_RATE = TWO_PI * 2.0  # rad/s of the forced angle
    RAMP_TIME = 0.2

    def __init__(self, dt: float, current: float) -> None:
        self.dt = dt
        self.current = current
        self.angle = 0.0
        self.time = 0.0
        self.samples: list[tuple[float, float, int]] = []
        self._rate = 0.0
        self.steady_time = 0.0
        """How long the sweep has turned at its full rate (the rotor's lag has settled after a while)."""

    def ramp_rate(self, direction: int) -> None:
        """Slew the sweep speed so the rotor is not kicked into oscillation."""
        target = direction * self.ELECTRICAL_RATE
        step = self.ELECTRICAL_RATE * self.dt / self.RAMP_TIME
        if abs(target - self._rate) <= step:
            self._rate = target
            self.steady_time += self.dt
        else:
            self._rate += math.copysign(step, target - self._rate)
            self.steady_time = 0.0
        self.angle += self._rate * self.dt

    def sample(self, turns: float, direction: int) -> None:
        self.samples.append((self.angle, turns, direction))


def circular_offset(samples: list[tuple[float, float, int]], pole_pairs: int, phase_sign: int) -> tuple[float, float]:
    """Offset in electrical turns (0..1) and the agreement (1 = all samples of each sweep agree).

    The rotor lags the field by the same angle turning forward and backward (friction, the damping drag), so
    the offset is the circular midpoint of the two sweeps' means; the agreement is the smaller mean resultant
    length of the two sweeps (an oscillating or slipping rotor spreads its samples)."""
    means = []
    for direction in (1, -1):
        x = y = 0.0
        count = 0
        for angle, turns, sweep in samples:
            if sweep == direction:
                value = TWO_PI * (phase_sign * angle / TWO_PI - pole_pairs * turns)
                x += math.cos(value)
                y += math.sin(value)
                count += 1
        if count:
            means.append((math.atan2(y, x), math.hypot(x, y) / count))
    if not means:
        return 0.0, 0.0
    first = means[0][0]
    middle = first + sum(((m - first + math.pi) % TWO_PI - math.pi) for m, _ in means) / len(means)
    return (middle / TWO_PI) % 1.0, min(r for _, r in means)


class _SweepProcedure:
    """A phasing procedure driven by a forced current vector: align, then sweep; `result` or `failed_reason`."""

    MIN_AGREEMENT = 0.95

    def __init__(self, dt: float, current: float) -> None:
        self.sweep = ForcedVectorSweep(dt, current)
        self.result: PhasingResult | None = None
        self.failed_reason = ""
        self._phase = "align"
        self._count = 0

    @property
    def angle(self) -> float:
        return self.sweep.angle

    @property
    def current(self) -> float:
        return self.sweep.current

    def _tick(self, turns: float) -> bool:
        """Advance the clock one period; True while the rotor is still aligning (it then starts "forward")."""
        sweep = self.sweep
        sweep.time += sweep.dt
        self._count += 1
        if self._phase != "align":
            return False
        if sweep.time >= sweep.ALIGN_TIME:
            self._phase = "forward"
            self._sweep_started(turns)
        return True

    def _sweep_started(self, turns: float) -> None:
        """Hook: the alignment is over at sensor position `turns`."""

    SETTLE_TIME = 0.0
    """Samples are taken once the sweep has turned this long at its full rate."""

    def _ramp_and_sample(self, direction: int, turns: float) -> None:
        self.sweep.ramp_rate(direction)
        if self._count % 8 == 0 and self.sweep.steady_time >= self.SETTLE_TIME:
            self.sweep.sample(turns, direction)

    def _fail(self, reason: str) -> bool:
        self.failed_reason = reason
        self._phase = "done"
        return True


class AutoPhasing(_SweepProcedure):
    """'apha'. Drive it with `step(turns)`; read `angle`/`current` for the forced vector each period."""

    MAX_ELECTRICAL_TURNS = 26
    SETTLE_TIME = 0.2
    SAMPLE_TIME = 0.2

    def __init__(self, dt: float, current: float) -> None:
        super().__init__(dt, current)
        self._start_turns = 0.0
        self._electrical_turns = 0.0
        self._direction = 1

    def _sweep_started(self, turns: float) -> None:
        self._start_turns = turns

    def step(self, turns: float) -> bool:
        """Advance one period with the sensor position in mechanical turns; True when finished."""
        if self._tick(turns):
            return False
        sweep = self.sweep
        if self._phase == "forward":
            self._ramp_and_sample(+1, turns)
            moved = turns - self._start_turns
            if abs(moved) >= 1.0 and not self._electrical_turns:
                self._electrical_turns = sweep.angle / TWO_PI
                self._direction = 1 if moved > 0 else -1
            if self._electrical_turns and sweep.steady_time >= self.SETTLE_TIME + self.SAMPLE_TIME:
                self._phase = "backward"  # one revolution seen and enough settled samples
            elif sweep.angle / TWO_PI > self.MAX_ELECTRICAL_TURNS:
                return self._fail("the shaft did not follow the rotating field (blocked or loaded?)")
            return False
        if self._phase == "backward":
            self._ramp_and_sample(-1, turns)
            if sweep.angle <= 0.0:
                sweep.angle = 0.0
                return self._finish()
            return False
        return True

    def _finish(self) -> bool:
        pole_pairs = round(self._electrical_turns)
        if not 1 <= pole_pairs <= 24:
            return self._fail(f"implausible pole pairs {self._electrical_turns:.2f}")
        offset, agreement = circular_offset(self.sweep.samples, pole_pairs, self._direction)
        if agreement < self.MIN_AGREEMENT:
            return self._fail(f"the rotor did not follow the field evenly (agreement {agreement:.2f})")
        self.result = PhasingResult(pole_pairs, self._direction, round(offset * 65536) % 65536)
        self._phase = "done"
        return True


class MotorPhasing(_SweepProcedure):
    """'mcal': offset only, with known pole pairs and phase order (±1 electrical turn around the start)."""

    def __init__(self, dt: float, current: float, pole_pairs: int, phase_sign: int) -> None:
        super().__init__(dt, current)
        self.pole_pairs = pole_pairs
        self.phase_sign = phase_sign

    def step(self, turns: float) -> bool:
        if self._tick(turns):
            return False
        sweep = self.sweep
        self._ramp_and_sample(1 if self._phase == "forward" else -1, turns)
        if self._phase == "forward" and sweep.angle >= TWO_PI:
            self._phase = "backward"
        elif self._phase == "backward" and sweep.angle <= 0.0:
            sweep.angle = 0.0
            offset, agreement = circular_offset(sweep.samples, self.pole_pairs, 1)
            if agreement < self.MIN_AGREEMENT:
                self.failed_reason = f"the rotor did not follow the field (agreement {agreement:.2f})"
            else:
                self.result = PhasingResult(self.pole_pairs, self.phase_sign, round(offset * 65536) % 65536)
            return True
        return False
