"""Operation modes (manual §3.2.3): set-point generation and the mode-specific control/status word bits.

Each handler is asked, once per control period while the drive follows set-points, to set the loop references;
`status_bits()` gives status word bits 10 (target reached), 12 and 13 for its mode.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import TYPE_CHECKING

from servostudio.sim.drive import errors
from servostudio.sim.drive.homing import FAST, Homing, HomingInputs, HomingStatus
from servostudio.sim.drive.loops import MODE_POSITION, MODE_TORQUE, MODE_VELOCITY
from servostudio.sim.drive.setpoints import PositionProfile, SmoothedProfile, VelocityRamp

if TYPE_CHECKING:
    from servostudio.sim.drive.behaviour import DriveBehaviour

BIT_TARGET_REACHED = 1 << 10
BIT_12 = 1 << 12
BIT_13 = 1 << 13
CW_NEW_SET_POINT = 1 << 4
CW_CHANGE_IMMEDIATELY = 1 << 5
CW_RELATIVE = 1 << 6
CW_HALT = 1 << 8
U32_OFF = 0xFFFFFFFF


class ModeHandler:
    def __init__(self, drive: DriveBehaviour) -> None:
        self.drive = drive

    def configure(self) -> None:
        """Parameters were re-read: convert what the handler uses every period."""

    def enter(self) -> None:
        """The mode takes over the loops (enable, mode change): start from the actual state, no jump."""

    def control_word(self, control_word: int, previous: int) -> None:
        """Mode bits changed (called in every state; the handler checks whether it may act)."""

    def step(self) -> None:
        raise NotImplementedError

    def status_bits(self) -> int:
        return 0

    def not_following(self) -> int:
        """The drive does not follow the mode's set-points (any state but Operation Enabled; called with every
        status word update there): the status bits the mode still shows."""
        return 0

    @property
    def uses_limit_switches(self) -> bool:
        """True while the mode itself runs into the limit switches (homing): the drive then does not stop it there."""
        return False

    def limit_switch_stop(self) -> None:
        """A limit switch in the direction of travel stopped the motion: drop what the generator was doing."""

    def current_limit(self) -> float:
        """The mode's own current limit (A) below the drive's: none, except where a mode pushes at a limit."""
        return math.inf


class ProfilePosition(ModeHandler):
    """PP: set-point handshake (CW4 ↑ → SW12), change immediately (CW5), relative (CW6), one buffered set-point,
    target reached with window 0x6067 held for 0x6068 ms."""

    def __init__(self, drive: DriveBehaviour) -> None:
        super().__init__(drive)
        self.generator = SmoothedProfile(drive.dt)
        self.target_user = 0.0
        self.acknowledged = False
        self.queued: tuple[float, float, float, float] | None = None
        self.in_window_time = 0.0
        self.reached = True

    def enter(self) -> None:
        drive = self.drive
        self.generator.reset(drive.loops.position)
        self.target_user = drive.actual_position_user()
        self.queued = None
        self.reached = True
        self.in_window_time = 0.0

    def control_word(self, control_word: int, previous: int) -> None:
        rising = control_word & CW_NEW_SET_POINT and not previous & CW_NEW_SET_POINT
        if rising and self.drive.device_control.follows_set_points:
            self._accept(control_word)
        if not control_word & CW_NEW_SET_POINT and self.queued is None:
            self.acknowledged = False

    def _accept(self, control_word: int) -> None:
        drive = self.drive
        if self.queued is not None and not control_word & CW_CHANGE_IMMEDIATELY:
            return  # buffer full: the set-point is not acknowledged
        value = float(drive.p.get("target_position", 0))
        base = self.queued[0] if self.queued is not None else self.target_user
        target_user = base + value if control_word & CW_RELATIVE else value
        units = drive.units
        speed = float(drive.p.get("profile_velocity", 0))
        limit = float(drive.p.get("max_profile_velocity", 0))
        if limit > 0:
            speed = min(speed, limit)
        speed = min(units.speed_to_rad(speed), drive.max_speed)
        set_point = (
            target_user,
            speed,
            units.accel_to_rad(float(drive.p.get("profile_acceleration", 0))),
            units.accel_to_rad(float(drive.p.get("profile_deceleration", 0))),
        )
        self.acknowledged = True
        if control_word & CW_CHANGE_IMMEDIATELY or self.generator.done:
            self.queued = None
            self._start(set_point)
        else:
            self.queued = set_point

    def _start(self, set_point: tuple[float, float, float, float]) -> None:
        target_user, speed, accel, decel = set_point
        self.target_user = target_user
        drive = self.drive
        window = 1
        if int(drive.p.get("motion_profile_type", 0)) == -1:
            # S-curve: smooth over the time the trapezoid needs to reach its speed (at most 0.2 s)
            window = max(1, round(min(speed / max(accel, 1e-9), 0.2) / drive.dt))
        self.generator.move_to(drive.user_to_rad_position(target_user), speed, accel, decel, window)
        self.reached = False
        self.in_window_time = 0.0

    def limit_switch_stop(self) -> None:
        """A limit switch in the direction of travel: stop at maximum deceleration, drop the move."""
        self.generator.reset(self.drive.loops.position)
        self.queued = None
        self.target_user = self.drive.actual_position_user()

    def step(self) -> None:
        drive = self.drive
        generator = self.generator
        generator.step()
        if generator.done and self.queued is not None:
            self._start(self.queued)
            self.queued = None
            if not drive.control_word & CW_NEW_SET_POINT:
                self.acknowledged = False
        loops = drive.loops
        loops.mode = MODE_POSITION
        loops.position_ref = generator.position
        loops.velocity_ff = generator.velocity
        loops.accel_ff = generator.acceleration
        if generator.done and not self.reached:
            window = float(drive.p.get("position_window", 0))
            if window <= 0 or abs(drive.actual_position_user() - self.target_user) <= window:
                self.in_window_time += drive.dt
                if self.in_window_time * 1000.0 >= float(drive.p.get("position_window_time", 0)):
                    self.reached = True
            else:
                self.in_window_time = 0.0

    def status_bits(self) -> int:
        bits = 0
        if self.reached:
            bits |= BIT_TARGET_REACHED
        if self.acknowledged:
            bits |= BIT_12
        if self.drive.following_error_active:
            bits |= BIT_13
        return bits


class ProfileVelocity(ModeHandler):
    """PV: target from the 0x30FF source (default 0x60FF), ramps 0x6083/0x6084, halt (CW8), window and
    threshold timers for SW10 and SW12."""

    def __init__(self, drive: DriveBehaviour) -> None:
        super().__init__(drive)
        self.ramp = VelocityRamp(drive.dt)
        self.target = 0.0
        self.window_time = 0.0
        self.threshold_time = 0.0
        self.reached = False
        self.standstill = False
        self._timer_time = 0.0
        self.limit = math.inf
        self.speed_unit = 1.0
        self.read_target: Callable[[], float] = lambda: 0.0
        self.accel = self.decel = 1.0

    def enter(self) -> None:
        self.ramp.velocity = self.drive.loops.speed
        self.window_time = self.threshold_time = 0.0
        self._timer_time = self.drive.time

    def configure(self) -> None:
        """Parameters changed: convert the limit and the ramps once."""
        drive = self.drive
        units = drive.units
        limit_user = float(drive.p.get("max_profile_velocity", 0))
        self.limit = min(drive.max_speed, units.speed_to_rad(limit_user) if limit_user > 0 else math.inf)
        self.speed_unit = units.speed_to_rad(1.0)  # rad/s per user unit/s, for the per-period conversion
        self.read_target = drive.pointer_reader("target_velocity_source", "target_velocity")
        self.accel = units.accel_to_rad(float(drive.p.get("profile_acceleration", 0)))
        self.decel = units.accel_to_rad(float(drive.p.get("profile_deceleration", 0)))

    def step(self) -> None:
        drive = self.drive
        target = self.read_target() * self.speed_unit
        limit = self.limit
        if target > limit:
            target = limit
        elif target < -limit:
            target = -limit
        if drive.halted or drive.limit_blocks(target):
            target = 0.0
        self.target = target
        velocity = self.ramp.step(target, self.accel, self.decel)
        loops = drive.loops
        loops.mode = MODE_VELOCITY
        loops.velocity_ref = velocity
        loops.velocity_ff = 0.0
        loops.accel_ff = 0.0

    def _timers(self) -> None:
        """Window and threshold timers, advanced by the time since the last status update."""
        drive = self.drive
        elapsed = drive.time - self._timer_time
        self._timer_time = drive.time
        actual = drive.units.speed_to_user(drive.loops.speed)
        window = float(drive.p.get("velocity_window", 0))
        target_user = drive.units.speed_to_user(self.target)
        if window > 0 and abs(actual - target_user) <= window:
            self.window_time += elapsed
        elif window > 0:
            self.window_time = 0.0
        if window > 0:
            self.reached = self.window_time * 1000.0 >= float(drive.p.get("velocity_window_time", 0))
        else:
            self.reached = self.ramp.velocity == self.target
        threshold = float(drive.p.get("velocity_threshold", 0))
        if threshold > 0 and abs(actual) <= threshold:
            self.threshold_time += elapsed
        else:
            self.threshold_time = 0.0
        self.standstill = threshold > 0 and self.threshold_time * 1000.0 >= float(
            drive.p.get("velocity_threshold_time", 0)
        )

    def status_bits(self) -> int:
        self._timers()
        return (BIT_TARGET_REACHED if self.reached else 0) | (BIT_12 if self.standstill else 0)


class ProfileTorque(ModeHandler):
    """PT: target torque (‰ of 0x6075) from the 0x3071 source, slope 0x6087 ‰/s, halt → 0."""

    def __init__(self, drive: DriveBehaviour) -> None:
        super().__init__(drive)
        self.current = 0.0
        self.target = 0.0
        self.read_target: Callable[[], float] = lambda: 0.0

    def configure(self) -> None:
        self.read_target = self.drive.pointer_reader("target_torque_source", "target_torque")

    def enter(self) -> None:
        self.current = 0.0

    def step(self) -> None:
        drive = self.drive
        rated = drive.rated_current
        target = self.read_target() / 1000.0 * rated
        if drive.halted or drive.limit_blocks(target):
            target = 0.0
        self.target = target
        slope = float(drive.p.get("torque_slope", 0)) / 1000.0 * rated * drive.dt
        difference = target - self.current
        if slope <= 0 or abs(difference) <= slope:
            self.current = target
        else:
            self.current += math.copysign(slope, difference)
        loops = drive.loops
        loops.mode = MODE_TORQUE
        loops.current_ref = self.current

    def status_bits(self) -> int:
        return BIT_TARGET_REACHED if self.current == self.target else 0


class HomingMode(ModeHandler):
    """HM: CW4 ↑ starts the method 0x6098, CW4 = 0 interrupts; SW13/12/10 as in the manual's table."""

    STALL_TIME = 0.02

    def __init__(self, drive: DriveBehaviour) -> None:
        super().__init__(drive)
        self.homing: Homing | None = None
        self.ramp = VelocityRamp(drive.dt)
        self.final = PositionProfile(drive.dt)
        self.position_ref = 0.0
        self.attained = False
        self.error = False
        self._stall_time = 0.0
        self._final_move = False

    def enter(self) -> None:
        self.position_ref = self.drive.loops.position
        self.ramp.velocity = 0.0
        self.homing = None
        self._final_move = False

    def setting(self, name: str, default: float) -> float:
        """A homing parameter by its profile name (a HOME sequence gives its own instead of 0x6098 …)."""
        return float(self.drive.p.get(name, default))

    def control_word(self, control_word: int, previous: int) -> None:
        if control_word & CW_NEW_SET_POINT and not previous & CW_NEW_SET_POINT:
            self.start()
        elif not control_word & CW_NEW_SET_POINT and previous & CW_NEW_SET_POINT:
            self.interrupt()

    def interrupt(self) -> None:
        """Drop the running method (CW4 = 0, or a HOME sequence ended early): the axis ramps to a stop."""
        self.homing = None
        self._final_move = False

    def start(self) -> None:
        """Start the homing method (CW4 rising edge, or a HOME sequence)."""
        drive = self.drive
        method = int(self.setting("homing_method", 35))
        self.attained = False
        self.error = False
        if not drive.device_control.follows_set_points and method != 35:
            self.error = True
            return
        self.homing = Homing(method)
        self.error = self.homing.status is HomingStatus.ERROR
        self._final_move = False
        self._stall_time = 0.0
        self.position_ref = drive.loops.position
        if method == 35 and not drive.device_control.follows_set_points:
            self._step_homing()

    def step(self) -> None:
        drive = self.drive
        loops = drive.loops
        if self._final_move:
            self.final.step()
            loops.mode = MODE_POSITION
            loops.position_ref = self.final.position
            loops.velocity_ff = self.final.velocity
            loops.accel_ff = self.final.acceleration
            if self.final.done:
                self._final_move = False
                self.attained = True
                self.position_ref = self.final.position
            return
        velocity = self._step_homing()
        self.position_ref += velocity * drive.dt
        loops.mode = MODE_POSITION
        loops.position_ref = self.position_ref
        loops.velocity_ff = velocity
        loops.accel_ff = self.ramp.acceleration

    def _step_homing(self) -> float:
        drive = self.drive
        homing = self.homing
        accel = drive.units.accel_to_rad(self.setting("homing_acceleration", 0)) or 1.0
        if homing is None or homing.status is not HomingStatus.RUNNING:
            return self.ramp.step(0.0, accel, accel)
        return self._follow_homing(homing, self._homing_move(homing), accel)

    def _homing_move(self, homing: Homing) -> tuple[int, int] | None:
        """One step of the running homing method against the drive's inputs; the step may end the run."""
        drive = self.drive
        physics = drive.physics
        loops = drive.loops
        stalled_now = loops.current_limited and abs(loops.speed) < 0.2 * abs(self.ramp.velocity) + 0.05
        self._stall_time = self._stall_time + drive.dt if stalled_now else 0.0
        inputs = HomingInputs(  # the drive's input functions: the plant's switches and the inputs routed to them
            negative_limit=drive.negative_limit,
            positive_limit=drive.positive_limit,
            home_switch=drive.home_switch,
            index_seen=physics.index_seen,
            index_position=drive.index_position_rad(),
            stalled=self._stall_time >= self.STALL_TIME,
            position=loops.position,
        )
        physics.index_seen = False
        pushing = homing.uses_current_limit
        move = homing.step(inputs)
        if pushing and (not homing.uses_current_limit or homing.status is not HomingStatus.RUNNING):
            # at the hard stop: the reference is where the axis stands, not where the ramp went
            self.position_ref = loops.position
            self.ramp.velocity = 0.0
            self._stall_time = 0.0
        return move

    def _follow_homing(self, homing: Homing, move: tuple[int, int] | None, accel: float) -> float:
        """The ramp's velocity for the homing step's outcome (a separate function: the step changed the status)."""
        drive = self.drive
        if homing.status is HomingStatus.FOUND:
            self._found(homing.home_position)
            return self.ramp.step(0.0, accel, accel)
        if homing.status is HomingStatus.ERROR:
            self.error = True
            return self.ramp.step(0.0, accel, accel)
        if move is None:
            return self.ramp.step(0.0, accel, accel)
        direction, speed_class = move
        name = "homing_speed_fast" if speed_class == FAST else "homing_speed_slow"
        speed = min(drive.units.speed_to_rad(self.setting(name, 0)), drive.max_speed)
        return self.ramp.step(direction * speed, accel, accel)

    def _found(self, home_rad: float) -> None:
        drive = self.drive
        drive.set_home(home_rad, self.setting("home_offset", 0))
        drive.write("homing_indicator", 1)
        if int(self.setting("end_on_home", 1)) and drive.device_control.follows_set_points:
            units = drive.units
            speed = units.speed_to_rad(self.setting("homing_speed_slow", 0)) or 1.0
            accel = units.accel_to_rad(self.setting("homing_acceleration", 0)) or 1.0
            self.final.reset(self.position_ref)
            self.final.velocity = self.ramp.velocity
            self.final.move_to(home_rad, max(speed, abs(self.ramp.velocity)), accel, accel)
            self.ramp.velocity = 0.0
            self._final_move = True
        else:
            self.attained = True

    @property
    def uses_current_limit(self) -> bool:
        return self.homing is not None and self.homing.status is HomingStatus.RUNNING and self.homing.uses_current_limit

    @property
    def uses_limit_switches(self) -> bool:
        return True

    def current_limit(self) -> float:
        """Methods −1..−4 push at the hard stop with the homing current limit."""
        return self.drive.homing_current() if self.uses_current_limit else math.inf

    def not_following(self) -> int:
        """A homing error stays visible (SW13) while the drive is disabled."""
        return self.status_bits() & BIT_13

    def status_bits(self) -> int:
        if self.error:
            standing = abs(self.drive.loops.speed) < 0.5
            return BIT_13 | (BIT_TARGET_REACHED if standing else 0)
        running = (self.homing is not None and self.homing.status is HomingStatus.RUNNING) or self._final_move
        if running:
            return 0
        if self.attained:
            return BIT_12 | BIT_TARGET_REACHED
        return BIT_TARGET_REACHED


class InterpolatedPosition(ModeHandler):
    """IP (linear sub-mode): each SYNC takes 0x60C1,1 and the loops move to it linearly over one 0x1006 period;
    CW4 enables the interpolation, SW12 shows it active."""

    def __init__(self, drive: DriveBehaviour) -> None:
        super().__init__(drive)
        self.previous = 0.0
        self.next = 0.0
        self.elapsed = 0.0
        self.period = 0.01
        self.fresh = False
        self.synced = 0
        address = drive.profile.address("ip_data")
        if address is not None and address in drive.store:
            drive.store.on_write(address[0], address[1], self.set_point_written)

    def enter(self) -> None:
        position = self.drive.loops.position
        self.previous = self.next = position
        self.elapsed = 0.0

    @property
    def active(self) -> bool:
        drive = self.drive
        return bool(drive.control_word & CW_NEW_SET_POINT) and drive.device_control.follows_set_points

    def set_point_written(self, index: int, sub: int, value: object) -> None:
        """Write hook of 0x60C1,1 (SDO or RPDO): a set-point arrived for the next SYNC."""
        self.fresh = True

    def sync(self) -> None:
        """SYNC: take the new set-point; error 50 when none arrived during the last cycle (manual L3805)."""
        drive = self.drive
        if not self.active:
            self.synced = 0
            return
        if not self.fresh and self.synced:
            drive.raise_error(errors.IP_UNDERFLOW)
            return
        self.fresh = False
        self.synced += 1
        current = self.previous + (self.next - self.previous) * min(1.0, self.elapsed / self.period)
        self.previous = current
        self.next = drive.user_to_rad_position(float(drive.live("ip_data", 0)))
        period_us = float(drive.live("sync_period", 10000))
        self.period = period_us * 1e-6 if period_us > 0 else 0.01
        self.elapsed = 0.0

    def step(self) -> None:
        drive = self.drive
        loops = drive.loops
        if not self.active:
            self.previous = self.next
            self.elapsed = 0.0
        self.elapsed += drive.dt
        fraction = min(1.0, self.elapsed / self.period)
        loops.mode = MODE_POSITION
        loops.position_ref = self.previous + (self.next - self.previous) * fraction
        loops.velocity_ff = (self.next - self.previous) / self.period if fraction < 1.0 else 0.0
        loops.accel_ff = 0.0
        drive.write("ip_output", drive.rad_to_user_position(loops.position_ref), integer=True)

    def status_bits(self) -> int:
        return BIT_12 if self.active else 0
