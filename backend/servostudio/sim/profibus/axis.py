"""The simulated TTA-PRO's axis: the shared plant, physics and servo loops of `servostudio.sim.drive`, with the
set-point generators its three modes need, in motor units (rad, rad/s, rad/s², A).

The regulator PNUs (716-719, 730-739, 830-832) are kept in the parameter memory, but the loops run the tuning
that commissioning gives the plant (`servostudio.sim.drive.commissioning`): the manual gives no physical scaling
for them, and this stage simulates no auto-tuning that would have to agree with such a scaling.
"""

from __future__ import annotations

import math

from servostudio.sim.drive import gains
from servostudio.sim.drive.commissioning import COMMISSIONING_BANDWIDTH_HZ
from servostudio.sim.drive.loops import (
    MODE_OFF,
    MODE_POSITION,
    MODE_TORQUE,
    MODE_VELOCITY,
    ServoLoops,
    low_pass_alpha,
    time_constant_alpha,
)
from servostudio.sim.drive.physics import AxisPhysics
from servostudio.sim.drive.setpoints import PositionProfile, VelocityRamp
from servostudio.sim.plant import Plant

STANDSTILL_SPEED = 0.5
"""rad/s: a stop at the current limit has ended below this speed."""
CURRENT_FILTER_HZ = 1500.0


class Axis:
    """One motor and its load, driven by position holds and profiles, speed ramps, current commands or a
    stop at the current limit."""

    def __init__(self, plant: Plant, dt: float) -> None:
        self.dt = dt
        self.physics = AxisPhysics(plant, dt)
        self.loops = ServoLoops(self.physics)
        self.profile = PositionProfile(dt)
        self.ramp = VelocityRamp(dt)
        self.braking = False
        configure_commissioned(self.loops, plant, dt)
        self.loops.measure()
        self.profile.reset(self.loops.position)

    @property
    def position(self) -> float:
        """Measured motor position, rad in sensor-counter coordinates."""
        return self.loops.position

    @property
    def speed(self) -> float:
        return self.loops.speed

    @property
    def stopped(self) -> bool:
        return abs(self.loops.speed) < STANDSTILL_SPEED

    # -- commands -------------------------------------------------------------------------------------------

    def power_off(self) -> None:
        self.loops.mode = MODE_OFF
        self.braking = False

    def power_on(self) -> None:
        """The power stage comes on holding the present position."""
        self.loops.reset_integrators()
        self.hold()

    def hold(self) -> None:
        self.braking = False
        self.profile.reset(self.loops.position)
        self.loops.mode = MODE_POSITION

    def move_to(self, target: float, speed: float, accel: float, decel: float) -> None:
        if self.loops.mode != MODE_POSITION or self.braking:
            self.hold()
        self.profile.move_to(target, speed, accel, decel)

    def ramp_stop(self, decel: float) -> None:
        """Stop the profile on the point a deceleration of `decel` reaches."""
        velocity = self.profile.velocity
        stop = self.profile.position + math.copysign(velocity * velocity / (2.0 * decel), velocity)
        self.move_to(stop, abs(velocity), decel, decel)

    def brake_at_limit(self) -> None:
        """Speed 0 through the speed loop at the current limit: the maximum deceleration (OFF3, CW4 = 0)."""
        self.braking = True
        self.loops.mode = MODE_VELOCITY
        self.loops.velocity_ref = 0.0

    def run_velocity(self, target: float, accel: float, decel: float) -> None:
        """Speed mode: the ramp slews towards `target` each period."""
        if self.loops.mode != MODE_VELOCITY or self.braking:
            self.ramp.velocity = self.loops.speed
            self.braking = False
            self.loops.mode = MODE_VELOCITY
        self.loops.velocity_ref = self.ramp.step(target, accel, decel)

    def run_current(self, current: float) -> None:
        self.braking = False
        self.loops.mode = MODE_TORQUE
        self.loops.current_ref = current

    @property
    def moving(self) -> bool:
        return not self.profile.done

    # -- one period -----------------------------------------------------------------------------------------

    def step(self, brake_released: bool) -> None:
        """One control period; the plant's holding brake (if fitted) holds while the drive does not release it."""
        loops = self.loops
        self.physics.brake_engaged = self.physics.plant.has_brake and not brake_released
        self.physics.power_stage_on = loops.mode != MODE_OFF
        loops.measure()
        if self.braking and self.stopped:
            self.hold()
        if loops.mode == MODE_POSITION:
            self.profile.step()
            loops.position_ref = self.profile.position
            loops.velocity_ff = self.profile.velocity
            loops.accel_ff = self.profile.acceleration
        loops.step()


def configure_commissioned(loops: ServoLoops, plant: Plant, dt: float) -> None:
    """The loop parameters of a drive commissioned for `plant` (the same rules as the CANopen drives')."""
    current = gains.current_loop_gains(plant.inductance, 0)
    tuned = gains.tuned_gains(
        plant.total_inertia, plant.torque_constant, COMMISSIONING_BANDWIDTH_HZ, viscous_friction=plant.viscous_friction
    )
    scale = tuned.kjv / gains.KJV_ONE
    loops.pole_pairs = plant.pole_pairs
    loops.phase_sign = plant.phase_sign
    loops.offset_turns = plant.sensor_offset / 65536.0
    loops.emf_constant = plant.torque_constant / 1.5
    loops.kp_q = loops.kp_d = current.kp_q * gains.CURRENT_KP_UNIT
    loops.ki_q = loops.ki_d = current.ki_q * gains.CURRENT_KI_UNIT
    loops.kpv = tuned.kpv * gains.KPV_UNIT * scale
    loops.kiv = tuned.kiv * gains.KIV_UNIT * scale
    loops.kbv = tuned.kbv * gains.KPV_UNIT * scale
    loops.kav = tuned.kav * gains.KAV_UNIT * scale
    loops.kpp = tuned.kpp * gains.KPP_UNIT
    loops.kfp = tuned.kfp / gains.KFP_FULL
    loops.speed_alpha = time_constant_alpha(gains.SPEED_FILTER_TAU[tuned.speed_filter], dt)
    loops.command_alphas = (low_pass_alpha(CURRENT_FILTER_HZ, dt),)
    loops.current_limit = plant.peak_current
