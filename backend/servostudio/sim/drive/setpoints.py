"""Set-point generators, run once per control period in motor units (rad, rad/s, rad/s²).

`PositionProfile` is an on-line trapezoidal generator: each period it accelerates toward the profile speed,
cruises, or brakes so that it stops exactly on the target; a new target can be given at any time (change set
immediately) and the generator blends from its current speed. `VelocityRamp` slews a speed toward a target
with separate acceleration and deceleration.
"""

from __future__ import annotations

import math


class PositionProfile:
    def __init__(self, dt: float) -> None:
        self.dt = dt
        self.position = 0.0
        self.velocity = 0.0
        self.acceleration = 0.0
        self.target = 0.0
        self.max_velocity = 1.0
        self.accel = 1.0
        self.decel = 1.0
        self.done = True

    def reset(self, position: float) -> None:
        """Hold at `position` (the actual position when a position mode starts)."""
        self.position = position
        self.target = position
        self.velocity = 0.0
        self.acceleration = 0.0
        self.done = True

    def move_to(self, target: float, max_velocity: float, accel: float, decel: float) -> None:
        self.target = target
        self.max_velocity = max(abs(max_velocity), 1e-9)
        self.accel = max(abs(accel), 1e-9)
        self.decel = max(abs(decel), 1e-9)
        self.done = False

    def step(self) -> None:
        if self.done:
            self.acceleration = 0.0
            return
        dt = self.dt
        v = self.velocity
        remaining = self.target - self.position
        direction = 1.0 if remaining > 0.0 else -1.0
        decel = self.decel
        if abs(remaining) <= abs(v) * dt * 0.5 + 0.5 * decel * dt * dt and abs(v) <= decel * dt * 2.0:
            self.acceleration = -v / dt
            self.position = self.target
            self.velocity = 0.0
            self.done = True
            return
        stopping = v * v / (2.0 * decel)
        moving_towards = v * direction > 0.0
        if moving_towards and stopping >= abs(remaining) - abs(v) * dt:
            new_v = v - direction * decel * dt
            if new_v * direction < 0.0:
                new_v = 0.0
            # land exactly: the speed that stops at the target with the deceleration
            exact = direction * math.sqrt(max(2.0 * decel * abs(remaining), 0.0))
            if abs(exact) < abs(new_v):
                new_v = exact
        elif not moving_towards and v != 0.0:
            new_v = v + direction * decel * dt
            if new_v * direction > 0.0:
                new_v = 0.0
        else:
            new_v = v + direction * self.accel * dt
            if abs(new_v) > self.max_velocity:
                new_v = math.copysign(max(self.max_velocity, abs(v) - decel * dt), new_v)
        self.acceleration = (new_v - v) / dt
        self.velocity = new_v
        self.position += 0.5 * (v + new_v) * dt


class VelocityRamp:
    def __init__(self, dt: float) -> None:
        self.dt = dt
        self.velocity = 0.0
        self.acceleration = 0.0

    def step(self, target: float, accel: float, decel: float) -> float:
        """Move the velocity toward `target`; slowing down (toward 0) uses `decel`."""
        v = self.velocity
        difference = target - v
        slowing = v != 0.0 and (difference * v < 0.0)
        rate = abs(decel if slowing else accel) * self.dt
        if abs(difference) <= rate:
            new_v = target
        else:
            new_v = v + math.copysign(rate, difference)
        self.acceleration = (new_v - v) / self.dt
        self.velocity = new_v
        return new_v


class SmoothedProfile:
    """A `PositionProfile` followed by a moving average over `window` periods (0x6086 = −1, S-curve).

    Averaging the trapezoid's positions over a time T turns each acceleration step into a linear ramp lasting T
    (limited jerk) and keeps the end position exactly; a window of 1 is the plain trapezoid.
    """

    def __init__(self, dt: float) -> None:
        self.dt = dt
        self.trapezoid = PositionProfile(dt)
        self.window = 1
        self.position = 0.0
        self.velocity = 0.0
        self.acceleration = 0.0
        self._samples: list[float] = [0.0]
        self._next = 0
        self._sum = 0.0

    @property
    def done(self) -> bool:
        return self.trapezoid.done and self.position == self.trapezoid.target

    @property
    def target(self) -> float:
        return self.trapezoid.target

    def reset(self, position: float) -> None:
        self.trapezoid.reset(position)
        self._fill(position)

    def move_to(self, target: float, max_velocity: float, accel: float, decel: float, window: int = 1) -> None:
        """Start a move; the smoothing window can only change when the profile is at rest."""
        if self.done and window != self.window:
            self.window = max(1, window)
            self._fill(self.position)
        self.trapezoid.move_to(target, max_velocity, accel, decel)

    def _fill(self, position: float) -> None:
        self._samples = [position] * self.window
        self._sum = position * self.window
        self._next = 0
        self.position = position
        self.velocity = 0.0
        self.acceleration = 0.0

    def step(self) -> None:
        trapezoid = self.trapezoid
        trapezoid.step()
        if self.window == 1:
            self.position = trapezoid.position
            self.velocity = trapezoid.velocity
            self.acceleration = trapezoid.acceleration
            return
        new = trapezoid.position
        self._sum += new - self._samples[self._next]
        self._samples[self._next] = new
        self._next = (self._next + 1) % self.window
        position = self._sum / self.window
        if trapezoid.done and all(sample == new for sample in self._samples):
            position = new
            self._sum = new * self.window
        velocity = (position - self.position) / self.dt
        self.acceleration = (velocity - self.velocity) / self.dt
        self.velocity = velocity
        self.position = position
