"""The set-point generators of the sequence types POS, SPEED and TORQUE, and the stop that ends a program.

A motion owns the loop references for as long as its sequence runs and after it, until the next sequence takes
them over. It starts from where the previous one left the reference (`Carry`: position and speed), so chained
sequences join without a jump: a POS with Decel = 0 or a SPEED with DecelTime = 0 hands its speed on to the next
sequence (the manual's combined profiles, L9799–9818 and L9936–9990). Each `step` reports the phases it reached
in that control period (`phases`); `arrived` says the motion is over, after which the sequencer counts the Tempo.
Times are ms as in 0x3611 ("AccelTime" is the time the speed change takes); speeds and positions are the user
units of the factor group, converted once when the motion starts.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

from servostudio.sim.drive.loops import MODE_POSITION, MODE_VELOCITY, ServoLoops
from servostudio.sim.drive.sequencer.phases import CRUISE, DECEL, HOLD, INPOS, NONE
from servostudio.sim.drive.sequencer.record import RELATIVE, SequenceRecord
from servostudio.sim.drive.setpoints import PositionProfile

if TYPE_CHECKING:
    from servostudio.sim.drive.behaviour import DriveBehaviour

CAPTURED_POSITION = (0x360B, 0)
CURRENT_LIMIT_PERIODS = 4
"""Control periods (1 ms) the current must stay at its limit before a TORQUE sequence holds it."""


@dataclass(frozen=True)
class Carry:
    """Where the previous motion left the reference: position (rad) and speed (rad/s)."""

    position: float
    velocity: float


def carry_of(loops: ServoLoops) -> Carry:
    """The reference the loops follow now (the actual position when they do not follow a position)."""
    if loops.mode == MODE_POSITION:
        return Carry(loops.position_ref, loops.velocity_ff)
    if loops.mode == MODE_VELOCITY:
        return Carry(loops.position, loops.velocity_ref)
    return Carry(loops.position, 0.0)


def ramp_rate(start: float, target: float, milliseconds: int) -> float:
    """The rate (rad/s²) that changes the speed from `start` to `target` in `milliseconds` (0: at once)."""
    return abs(target - start) / (milliseconds / 1000.0) if milliseconds else math.inf


def profile_deceleration(drive: DriveBehaviour) -> float:
    """How a stopped or ended program brakes a moving reference: 0x6084, else 0x6085, else at once."""
    for name in ("profile_deceleration", "quick_stop_deceleration"):
        value = float(drive.p.get(name, 0))
        if value > 0:
            return drive.units.accel_to_rad(value)
    return math.inf


def toward(value: float, target: float, change: float) -> float:
    """`value` moved by at most `change` toward `target`."""
    if abs(target - value) <= change:
        return target
    return value + math.copysign(change, target - value)


def sequence_speed(drive: DriveBehaviour, user_speed: int) -> float:
    """A sequence's Speed in rad/s, within the motor's maximum speed (the sign stays)."""
    speed = drive.units.speed_to_rad(user_speed)
    return max(-drive.max_speed, min(drive.max_speed, speed))


class Reference:
    """A position reference driven by a speed ramp: the speed moves toward a target, the position integrates it."""

    def __init__(self, dt: float, carry: Carry) -> None:
        self.dt = dt
        self.position = carry.position
        self.velocity = carry.velocity
        self.acceleration = 0.0

    def ramp_to(self, target: float, rate: float) -> bool:
        """One period toward the speed `target` at `rate` (inf: at once); True once the speed is there."""
        velocity = self.velocity
        new = toward(velocity, target, rate * self.dt)
        self.acceleration = (new - velocity) / self.dt if math.isfinite(rate) else 0.0
        self.velocity = new
        self.position += 0.5 * (velocity + new) * self.dt
        return new == target

    def coast(self) -> None:
        """One period at the present speed."""
        self.ramp_to(self.velocity, 0.0)

    def run_at(self, velocity: float) -> None:
        """One period whose speed goes to `velocity` (a ramp computed by the caller)."""
        self.advance(0.5 * (self.velocity + velocity) * self.dt, velocity)

    def advance(self, distance: float, velocity: float) -> None:
        """One period that moves the reference by `distance`, ending at `velocity`."""
        self.acceleration = (velocity - self.velocity) / self.dt
        self.velocity = velocity
        self.position += distance

    def follow(self, loops: ServoLoops) -> None:
        follow(loops, self.position, self.velocity, self.acceleration)


def follow(loops: ServoLoops, position: float, velocity: float, acceleration: float) -> None:
    """The loops follow a position reference with its speed and acceleration feed-forward."""
    loops.mode = MODE_POSITION
    loops.position_ref = position
    loops.velocity_ff = velocity
    loops.accel_ff = acceleration


class Motion:
    """One sequence's set-point generator. Subclasses implement `_phases`, which moves the references."""

    uses_limit_switches = False

    def __init__(self, drive: DriveBehaviour) -> None:
        self.drive = drive
        self.loops = drive.loops
        self.dt = drive.dt
        self.arrived = False
        self.failed = False
        self._seen = NONE
        self._pending = NONE

    def step(self) -> int:
        """One control period; the phases reached in it, each reported once."""
        phases = (self._phases() | self._pending) & ~self._seen
        self._pending = NONE
        self._seen |= phases
        return phases

    def _phases(self) -> int:
        raise NotImplementedError

    def end_early(self) -> Motion:
        """An end condition or a stop: leave the running phase. Returns the motion that finishes the sequence."""
        return StopMotion(self.drive, carry_of(self.loops), profile_deceleration(self.drive))

    def current_limit(self) -> float:
        """The sequence's own current limit (A): none but a TORQUE sequence's and a pushing HOME's."""
        return math.inf


class StopMotion(Motion):
    """Brakes the reference to standstill at `deceleration` and holds it there: an interrupted sequence, a stopped
    or ended program, and the sequencer at rest (a carry without speed arrives at once)."""

    def __init__(self, drive: DriveBehaviour, carry: Carry, deceleration: float) -> None:
        super().__init__(drive)
        self.reference = Reference(drive.dt, carry)
        self.deceleration = deceleration
        self._braking = DECEL if carry.velocity else NONE

    @classmethod
    def holding(cls, drive: DriveBehaviour) -> StopMotion:
        """Hold the actual position (the mode takes over the loops)."""
        return cls(drive, Carry(drive.loops.position, 0.0), math.inf)

    def step(self) -> int:
        """Standing: only the hold (the sequencer at rest runs this every period in sequence mode)."""
        if self.arrived:
            follow(self.loops, self.reference.position, 0.0, 0.0)
            return NONE
        return super().step()

    def _phases(self) -> int:
        stopped = self.reference.ramp_to(0.0, self.deceleration)
        self.reference.follow(self.loops)
        self.arrived = stopped
        return self._braking | (HOLD if stopped else NONE)

    def end_early(self) -> Motion:
        return self


class PositionMotion(Motion):
    """POS with a deceleration: the profile generator of Profile Position (trapezoid) to the target, from the
    carried reference and speed. CRUISE at the profile speed, DECEL when braking begins, HOLD when the reference
    is on the target, INPOS when the position is within 0x6067 of it (at once with 0x6067 = 0)."""

    def __init__(self, drive: DriveBehaviour, record: SequenceRecord, carry: Carry) -> None:
        super().__init__(drive)
        self.target_user = position_target(drive, record, carry)
        self.speed = position_speed(drive, record)
        self.window = float(drive.p.get("position_window", 0))
        target = drive.user_to_rad_position(self.target_user)
        deceleration = drive.units.accel_to_rad(record.deceleration)
        self.profile = PositionProfile(drive.dt)
        self.profile.reset(carry.position)
        self.profile.velocity = carry.velocity
        self.profile.move_to(target, self.speed, position_acceleration(drive, record), deceleration)

    def _phases(self) -> int:
        profile = self.profile
        profile.step()
        follow(self.loops, profile.position, profile.velocity, profile.acceleration)
        speed = abs(profile.velocity)
        phases = CRUISE if speed >= self.speed * (1.0 - 1e-9) else NONE
        if profile.acceleration * profile.velocity < 0.0 and speed < self.speed:
            phases |= DECEL
        if profile.done:
            phases |= HOLD | self._in_position()
        return phases

    def _in_position(self) -> int:
        if self.window > 0 and abs(self.drive.actual_position_user() - self.target_user) > self.window:
            return NONE
        self.arrived = True
        return INPOS

    def end_early(self) -> Motion:
        deceleration = self.profile.decel
        return StopMotion(self.drive, carry_of(self.loops), deceleration)


class PassingMotion(Motion):
    """POS with Decel = 0: accelerates to its speed and passes the target without braking ("no deceleration",
    L9799–9818); HOLD as the reference crosses it, and the next sequence goes on from there at speed."""

    def __init__(self, drive: DriveBehaviour, record: SequenceRecord, carry: Carry) -> None:
        super().__init__(drive)
        self.reference = Reference(drive.dt, carry)
        self.target = drive.user_to_rad_position(position_target(drive, record, carry))
        self.direction = 1.0 if self.target >= carry.position else -1.0
        self.velocity = self.direction * position_speed(drive, record)
        self.acceleration = position_acceleration(drive, record)

    def _phases(self) -> int:
        reference = self.reference
        if self.arrived:
            reference.coast()
            reference.follow(self.loops)
            return NONE
        phases = CRUISE if reference.ramp_to(self.velocity, self.acceleration) else NONE
        if (self.target - reference.position) * self.direction <= 0.0:
            reference.position = self.target
            self.arrived = True
            phases |= HOLD
        reference.follow(self.loops)
        return phases


def position_motion(drive: DriveBehaviour, record: SequenceRecord, carry: Carry) -> Motion:
    """A POS sequence's motion: braking to the target, or passing it when Decel is 0."""
    if record.deceleration:
        return PositionMotion(drive, record, carry)
    return PassingMotion(drive, record, carry)


def position_target(drive: DriveBehaviour, record: SequenceRecord, carry: Carry) -> int:
    """The target in user units: Position, or REL (sub 21 bit 0) from where the previous sequence left the
    reference (rounded to the user unit, so a chain of relative moves does not drift)."""
    if not record.configuration & RELATIVE:
        return record.position
    return round(drive.rad_to_user_position(carry.position)) + record.position


def position_speed(drive: DriveBehaviour, record: SequenceRecord) -> float:
    """|Speed| in rad/s; 0 takes the profile velocity 0x6081 (a POS sequence always moves)."""
    user = abs(record.speed) or float(drive.p.get("profile_velocity", 0))
    return min(drive.units.speed_to_rad(user), drive.max_speed)


def position_acceleration(drive: DriveBehaviour, record: SequenceRecord) -> float:
    """Accel (sub 17, acceleration units); 0 takes the profile acceleration 0x6083."""
    return drive.units.accel_to_rad(record.acceleration or float(drive.p.get("profile_acceleration", 0)))


class SpeedMotion(Motion):
    """SPEED: ramps to Speed in AccelTime (CRUISE), runs RunTime ms (65535: until an end condition or a stop),
    then brakes to standstill in DecelTime (DECEL, HOLD); with DecelTime = 0 it ends at speed after the running
    phase, for the next sequence to go on from ("for combining profiles")."""

    def __init__(self, drive: DriveBehaviour, record: SequenceRecord, carry: Carry) -> None:
        super().__init__(drive)
        self.record = record
        self.reference = Reference(drive.dt, carry)
        self.target = sequence_speed(drive, record.speed)
        self.rate = ramp_rate(carry.velocity, self.target, record.acceleration_time)
        self.run_until = math.inf
        self.stage: Callable[[], int] = self._accelerate

    def _phases(self) -> int:
        phases = self.stage()
        self.reference.follow(self.loops)
        return phases

    def _accelerate(self) -> int:
        if not self.reference.ramp_to(self.target, self.rate):
            return NONE
        if not self.record.infinite:
            self.run_until = self.drive.time + self.record.run_time / 1000.0 - self.dt / 2
        self.stage = self._run
        return CRUISE | self._leave_when_run()

    def _run(self) -> int:
        self.reference.coast()
        return self._leave_when_run()

    def _leave_when_run(self) -> int:
        return self._leave_running() if self.drive.time >= self.run_until else NONE

    def _leave_running(self) -> int:
        """The running phase is over: brake in DecelTime, or end at speed with DecelTime 0."""
        if not self.record.deceleration_time:
            self.arrived = True
            self.stage = self._coast
            return NONE
        self.rate = ramp_rate(self.reference.velocity, 0.0, self.record.deceleration_time)
        self.stage = self._brake
        return DECEL

    def _brake(self) -> int:
        if not self.reference.ramp_to(0.0, self.rate):
            return NONE
        self.arrived = True
        self.stage = self._coast
        return HOLD

    def _coast(self) -> int:
        self.reference.coast()
        return NONE

    def end_early(self) -> Motion:
        if self.stage in (self._accelerate, self._run):
            self._pending |= self._leave_running()
        return self


class TorqueMotion(Motion):
    """TORQUE: in the speed loop (so without a following error) at Speed, ramped in AccelTime, with the current
    limited to Torque ‰ of 0x6075. When the current has been at that limit for 1 ms it holds it (HOLD) for RunTime
    (65535: until an end condition or a stop), captures the position in 0x360B, then brakes the speed reference
    to zero in DecelTime (DECEL) and holds the position where it stands."""

    def __init__(self, drive: DriveBehaviour, record: SequenceRecord, carry: Carry) -> None:
        super().__init__(drive)
        self.record = record
        self.limit = abs(record.analog) / 1000.0 * drive.rated_current
        self.target = sequence_speed(drive, record.speed)
        self.velocity = carry.velocity
        self.rate = ramp_rate(carry.velocity, self.target, record.acceleration_time)
        self.hold_until = math.inf
        self.rest = carry.position
        self._limited_periods = 0
        self.stage: Callable[[], int] = self._push

    def _phases(self) -> int:
        return self.stage()

    def _push(self) -> int:
        target = 0.0 if self.drive.limit_blocks(self.target) else self.target
        phases = CRUISE if self._ramp(target, self.rate) else NONE
        self._limited_periods = self._limited_periods + 1 if self.loops.current_limited else 0
        if self._limited_periods >= CURRENT_LIMIT_PERIODS:
            if not self.record.infinite:
                self.hold_until = self.drive.time + self.record.run_time / 1000.0 - self.dt / 2
            self.stage = self._hold
            phases |= HOLD
        return phases

    def _hold(self) -> int:
        self._ramp(self.velocity, 0.0)
        return self._release() if self.drive.time >= self.hold_until else NONE

    def _release(self) -> int:
        """The holding is over: capture the position (0x360B), then brake the speed reference."""
        drive = self.drive
        drive.store.set(*CAPTURED_POSITION, round(drive.actual_position_user()))
        self.rate = ramp_rate(self.velocity, 0.0, self.record.deceleration_time)
        self.stage = self._brake
        return DECEL

    def _brake(self) -> int:
        if self._ramp(0.0, self.rate):
            self.arrived = True
            self.rest = self.loops.position
            self.stage = self._rest
        return NONE

    def _rest(self) -> int:
        follow(self.loops, self.rest, 0.0, 0.0)
        return NONE

    def _ramp(self, target: float, rate: float) -> bool:
        """The speed reference one period toward `target`, in the speed loop."""
        self.velocity = toward(self.velocity, target, rate * self.dt)
        loops = self.loops
        loops.mode = MODE_VELOCITY
        loops.velocity_ref = self.velocity
        loops.velocity_ff = loops.accel_ff = 0.0
        return self.velocity == target

    def end_early(self) -> Motion:
        if self.stage in (self._push, self._hold):
            self._pending |= self._release()
        return self

    def current_limit(self) -> float:
        return math.inf if self.arrived else self.limit
