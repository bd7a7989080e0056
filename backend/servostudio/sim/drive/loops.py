"""The drive's cascade: position loop → speed loop → current limit and filters → d/q current loop → voltages.

Structure (docs/control-loops.md, manual §3.2.2.8):

    ω_ref = KPp·(x_ref − x) + KFp·ω_ff                                  (position modes)
    e     = ω_ref − ω_m                   ω_m = speed measured from the sensor, first-order filter 0x30FA
    i_ref = KJv·(KPv·e + KIv·∫e − KCv·ω_m + KBv·ω_ff + KAv·α_ff) − KDv·dω_m/dt + 0x60B2
    i_ref → ±limit → + 0x30B3 → three first-order low-passes 0x30F9 → iq_ref  (id_ref = 0)
    v_dq  = PI(i_ref − i_measured) + (0, Ke·ω_m) in the frame of θ̂ = 2π·(pp·turns + offset/65536), |v| ≤ Vdc/√3
            (Ke = Kt/1.5 from the motor data 0x6410,11: back-EMF feed-forward)

The integrator leaks with corner KIvf and stops winding up while the current is limited.
"""

from __future__ import annotations

import math

from servostudio.sim.drive.physics import TWO_PI, AxisPhysics

MODE_OFF = 0
"""Power stage off: no voltages."""
MODE_POSITION = 1
MODE_VELOCITY = 2
MODE_TORQUE = 3
MODE_FORCED_VECTOR = 4
"""Open-loop current vector at a forced electrical angle (phasing procedures)."""
FORCED_Q_INTEGRAL = 40.0
"""V/(A·s): the forced vector's q axis is voltage-driven with only this slow integral (≈ 1 Hz at 1.5 Ω), so the
back-EMF of a rotor swinging about the field drives a braking current: electrical damping, whatever the phase
order. The mean q current still returns to 0, so a steadily turning field is not braked."""
FORCED_Q_RESISTANCE = 2.0
"""V/A: a small proportional term (a virtual series resistance) bounds that braking current."""


class ServoLoops:
    """Controller state plus the parameters it runs with (physical units, written by the behaviour)."""

    def __init__(self, physics: AxisPhysics) -> None:
        self.physics = physics
        self.dt = physics.dt
        # parameters
        self.pole_pairs = 1
        self.phase_sign = 1
        self.offset_turns = 0.0
        self.kp_q = self.ki_q = self.kp_d = self.ki_d = 0.0
        self.emf_constant = 0.0
        self.kpv = self.kiv = self.kcv = self.kbv = self.kav = 0.0
        self.kdv = 0.0
        self.integral_leak = 0.0
        self.derivative_alpha = 1.0
        self.kpp = 0.0
        self.kfp = 0.0
        self.speed_alpha = 1.0
        self.command_alphas: tuple[float, ...] = ()
        self.current_limit = 0.0
        self.torque_offset = 0.0
        self.torque_offset_2 = 0.0
        # inputs
        self.mode = MODE_OFF
        self.position_ref = 0.0
        self.velocity_ff = 0.0
        self.accel_ff = 0.0
        self.velocity_ref = 0.0
        self.current_ref = 0.0
        self.forced_angle = 0.0
        self.forced_current = 0.0
        # measurements and state
        self._rad_per_count = TWO_PI / physics.counts_per_turn
        self.position = physics.sensor_counts() * self._rad_per_count
        self.speed_raw = 0.0
        self.speed = 0.0
        self.speed_demand = 0.0
        self.current_demand = 0.0
        self.current_limited = False
        self.i_d = 0.0
        self.i_q = 0.0
        self._speed_integral = 0.0
        self._derivative = 0.0
        self._previous_speed = 0.0
        self._command_states = [0.0, 0.0, 0.0]
        self._vi_d = 0.0
        self._vi_q = 0.0

    def reset_integrators(self) -> None:
        """Called whenever the power stage switches on, so no stale state kicks the motor."""
        self._speed_integral = 0.0
        self._derivative = 0.0
        self._command_states = [0.0, 0.0, 0.0]
        self._vi_d = 0.0
        self._vi_q = 0.0

    def measure(self) -> None:
        """Sample the sensor once per period: position and filtered speed (always, also when disabled)."""
        physics = self.physics
        position = physics.sensor_counts() * self._rad_per_count
        self.speed_raw = (position - self.position) / self.dt
        self.position = position
        self.speed += self.speed_alpha * (self.speed_raw - self.speed)

    def step(self) -> None:
        """Run the loops for the current mode and apply the voltages to the physics for one period.

        The commutation angle and the current PI are written out here rather than called: this runs 4000 times
        per simulated second per axis."""
        physics = self.physics
        mode = self.mode
        phase_sign = self.phase_sign
        if mode == MODE_OFF:
            self.current_demand = 0.0
            self.i_d = self.i_q = 0.0
            physics.step(0.0, 0.0, 0.0, phase_sign)
            return
        if mode == MODE_FORCED_VECTOR:
            theta = self.forced_angle
            id_ref = self.forced_current
            iq_ref = 0.0
        else:
            theta = TWO_PI * (self.pole_pairs * self.position / TWO_PI + self.offset_turns)
            iq_ref = self._current_reference(mode)
            id_ref = 0.0
        self.current_demand = iq_ref
        i_d, i_q = physics.measured_currents(theta, phase_sign)
        self.i_d = i_d
        self.i_q = i_q
        # current PI with back-EMF feed-forward, voltage limited to Vdc/√3 (no integration while limited)
        error_d = id_ref - i_d
        error_q = iq_ref - i_q
        dt = self.dt
        vi_d = self._vi_d + self.ki_d * error_d * dt
        v_d = self.kp_d * error_d + vi_d
        if mode == MODE_FORCED_VECTOR:
            # q in voltage mode with a slow integral: the rotor's back-EMF drives a braking current (damping)
            vi_q = self._vi_q + FORCED_Q_INTEGRAL * error_q * dt
            v_q = FORCED_Q_RESISTANCE * error_q + vi_q
        else:
            vi_q = self._vi_q + self.ki_q * error_q * dt
            v_q = self.kp_q * error_q + vi_q + self.emf_constant * self.speed
        v_max = physics.dc_bus / 1.7320508075688772
        magnitude = math.sqrt(v_d * v_d + v_q * v_q)
        if magnitude > v_max:
            scale = v_max / magnitude
            v_d *= scale
            v_q *= scale
        else:
            self._vi_d = vi_d
            self._vi_q = vi_q
        physics.step(v_d, v_q, theta, phase_sign)

    def _current_reference(self, mode: int) -> float:
        speed = self.speed
        if mode == MODE_TORQUE:
            demand = self.current_ref + self.torque_offset
        else:
            if mode == MODE_POSITION:
                self.speed_demand = self.kpp * (self.position_ref - self.position) + self.kfp * self.velocity_ff
            else:
                self.speed_demand = self.velocity_ref
            error = self.speed_demand - speed
            derivative = (speed - self._previous_speed) / self.dt
            self._previous_speed = speed
            self._derivative += self.derivative_alpha * (derivative - self._derivative)
            demand = (
                self.kpv * error
                + self.kiv * self._speed_integral
                - self.kcv * speed
                + self.kbv * self.velocity_ff
                + self.kav * self.accel_ff
                - self.kdv * self._derivative
                + self.torque_offset
            )
            limit = self.current_limit
            winding = (demand >= limit and error > 0.0) or (demand <= -limit and error < 0.0)
            if not winding:
                self._speed_integral += (error - self.integral_leak * self._speed_integral) * self.dt
        limit = self.current_limit
        self.current_limited = demand > limit or demand < -limit
        if demand > limit:
            demand = limit
        elif demand < -limit:
            demand = -limit
        demand += self.torque_offset_2
        states = self._command_states
        for n, alpha in enumerate(self.command_alphas):
            states[n] += alpha * (demand - states[n])
            demand = states[n]
        return demand


def low_pass_alpha(cutoff_hz: float, dt: float) -> float:
    """Coefficient of a first-order low-pass y += α·(x − y) at `cutoff_hz` (exact for a step input)."""
    return 1.0 - math.exp(-TWO_PI * cutoff_hz * dt)


def time_constant_alpha(tau: float, dt: float) -> float:
    return 1.0 - math.exp(-dt / tau)
