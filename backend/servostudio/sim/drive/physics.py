"""Physics of one axis, advanced one control period at a time: PMSM, power stage, mechanics, DC bus, heat.

Electrical model (rotor d/q frame, amplitude-invariant transform, surface-magnet PMSM):

    L·did/dt = vd − R·id + ωe·L·iq
    L·diq/dt = vq − R·iq − ωe·L·id − Kt·ωm/1.5          torque T = Kt·iq

The drive does not know the rotor frame: it applies voltages in the frame of its own commutation angle θ̂
(from the sensor and 0x3410) with its own phase order. With S = (drive phase sign)·(true phase sign) and the
true electrical angle θt = 2π·(pp·turns + offset/65536), the drive frame maps to the rotor frame by
`real = R(δ)·diag(1, S)·drive`, δ = S·θ̂ − θt. A wrong offset makes δ ≠ 0 (torque ∝ cos δ); a wrong phase order
(S = −1) mirrors the q axis, so the torque reverses. The R/L part is integrated exactly (exponential), the
rest is held over the period, so the model is stable for any control period.

Pure-Python scalar math only: this runs 4000 times per simulated second per axis.
"""

from __future__ import annotations

import math

from servostudio.sim.plant import FEEDBACK_ENCODER, Plant

TWO_PI = 2.0 * math.pi
OVERCURRENT_FACTOR = 1.5
"""Hardware overcurrent trip: |i| above 1.5 × drive max current (0x6510,1)."""


class AxisPhysics:
    """State and integration of one axis. Positions in rad (motor shaft / load), currents in A (d/q amplitude)."""

    def __init__(self, plant: Plant, dt: float) -> None:
        self.plant = plant
        self.dt = dt
        self.theta_motor = plant.initial_position * TWO_PI
        self.omega_motor = 0.0
        self.theta_load = self.theta_motor
        self.omega_load = 0.0
        self.i_d = 0.0
        self.i_q = 0.0
        self.v_d = 0.0
        self.v_q = 0.0
        self.dc_bus = plant.dc_bus_voltage if plant.mains_on else 0.0
        self.mains_on = plant.mains_on
        self.temperature = plant.ambient_temperature
        self.power_stage_on = False
        self.brake_engaged = plant.has_brake
        self.braking_power = 0.0
        self.stopped_at_hard_stop = False
        self._inductance = plant.inductance / 2.0  # phase inductance from the phase-to-phase value
        self._inductance_pole_pairs = self._inductance * plant.pole_pairs
        self._rigid_inertia = plant.motor_inertia + plant.load_inertia
        self._copper_factor = 1.5 * plant.phase_resistance
        self._negative_stop = None if plant.negative_hard_stop is None else plant.negative_hard_stop * TWO_PI
        self._positive_stop = None if plant.positive_hard_stop is None else plant.positive_hard_stop * TWO_PI
        self._decay = math.exp(-plant.phase_resistance * dt / self._inductance)
        self._gain = (1.0 - self._decay) / plant.phase_resistance
        self._bus_decay = math.exp(-dt / (plant.supply_resistance * plant.dc_bus_capacitance))
        self._counts = plant.encoder_counts
        self._counter_zero = self._power_on_counter_zero()
        self._index_cycle = math.floor(self.motor_turns - plant.index_position)
        self.index_seen = False
        self.index_turns = 0.0
        self._frame: tuple[float, float, int] | None = None
        self._phase_sign = plant.phase_sign

    # -- sensor view --------------------------------------------------------------------------------------------

    @property
    def motor_turns(self) -> float:
        return self.theta_motor / TWO_PI

    @property
    def load_turns(self) -> float:
        return self.theta_load / TWO_PI

    def sensor_counts(self) -> int:
        """Quantised multi-turn position counter of the motor sensor, relative to its power-on zero."""
        return math.floor(self.theta_motor / TWO_PI * self._counts) - self._counter_zero

    def counter_turns(self, true_turns: float) -> float:
        """A true shaft position (turns) in the sensor counter's coordinates (unquantised)."""
        return true_turns - self._counter_zero / self._counts

    @property
    def counts_per_turn(self) -> int:
        return self._counts

    def _power_on_counter_zero(self) -> int:
        """A resolver is absolute within one turn (zero on a whole turn); an incremental encoder starts at 0."""
        counts = math.floor(self.motor_turns * self._counts)
        if self.plant.feedback == FEEDBACK_ENCODER:
            return counts
        return math.floor(self.motor_turns) * self._counts

    def power_cycle_sensor(self) -> None:
        """24 V reset: the incremental counter restarts (an encoder axis then needs motor phasing again)."""
        self._counter_zero = self._power_on_counter_zero()

    def true_electrical_angle(self) -> float:
        """θt in rad: the angle a perfectly phased drive computes (resolver counters are zero on a whole turn)."""
        plant = self.plant
        return TWO_PI * (plant.pole_pairs * self.theta_motor / TWO_PI + plant.sensor_offset / 65536.0)

    # -- one period ---------------------------------------------------------------------------------------------

    def measured_currents(self, theta_hat: float, phase_sign: int) -> tuple[float, float]:
        """Currents as the drive sees them in its own frame (inverse of the drive → rotor mapping).

        Also fixes the frame for the following `step` (the state does not change in between)."""
        c, sn, s = self._fix_frame(theta_hat, phase_sign)
        i_d = self.i_d
        i_q = self.i_q
        return c * i_d + sn * i_q, s * (-sn * i_d + c * i_q)

    def _fix_frame(self, theta_hat: float, phase_sign: int) -> tuple[float, float, int]:
        """The drive → rotor frame of this period (cosine and sine of the angle error, phase sign), kept for `step`."""
        plant = self.plant
        s = phase_sign * self._phase_sign
        delta = s * theta_hat - TWO_PI * (plant.pole_pairs * self.theta_motor / TWO_PI + plant.sensor_offset / 65536.0)
        frame = self._frame = (math.cos(delta), math.sin(delta), s)
        return frame

    def step(self, v_d_hat: float, v_q_hat: float, theta_hat: float, phase_sign: int) -> None:
        """Apply the drive-frame voltages for one period and advance everything.

        The rigid mechanics, the DC bus, the heat and the index pulse are written out here rather than called:
        this runs 4000 times per simulated second per axis."""
        plant = self.plant
        dt = self.dt
        if self.power_stage_on:
            frame = self._frame
            if frame is None:
                frame = self._fix_frame(theta_hat, phase_sign)
            c, sn, s = frame
            vq_m = s * v_q_hat
            v_d = c * v_d_hat - sn * vq_m
            v_q = sn * v_d_hat + c * vq_m
            omega = self.omega_motor
            lw = self._inductance_pole_pairs * omega
            i_d = self.i_d
            i_q = self.i_q
            decay = self._decay
            gain = self._gain
            i_d, i_q = (
                decay * i_d + gain * (v_d + lw * i_q),
                decay * i_q + gain * (v_q - lw * i_d - plant.torque_constant * omega / 1.5),
            )
        else:
            i_d = i_q = v_d = v_q = 0.0
        self.i_d = i_d
        self.i_q = i_q
        self.v_d = v_d
        self.v_q = v_q
        self._frame = None
        torque = plant.torque_constant * i_q
        if plant.two_mass:
            self._step_two_mass(torque, dt)
        else:
            omega = self.omega_motor
            driving = torque - plant.gravity_torque - plant.viscous_friction * omega
            friction = plant.coulomb_friction + (plant.brake_torque if self.brake_engaged else 0.0)
            if omega == 0.0:  # dry friction: the axis sticks while |driving torque| ≤ friction (see _coulomb_step)
                if abs(driving) <= friction:
                    new = 0.0
                else:
                    new = dt * (driving - math.copysign(friction, driving)) / self._rigid_inertia
            else:
                new = omega + dt * (driving - math.copysign(friction, omega)) / self._rigid_inertia
                if (new > 0.0) != (omega > 0.0):
                    new = 0.0
            theta = self.theta_motor + new * dt
            self.stopped_at_hard_stop = False
            low = self._negative_stop
            high = self._positive_stop
            if low is not None and theta <= low and new <= 0.0:
                theta = low
                new = 0.0
                self.stopped_at_hard_stop = True
            elif high is not None and theta >= high and new >= 0.0:
                theta = high
                new = 0.0
                self.stopped_at_hard_stop = True
            self.omega_motor = self.omega_load = new
            self.theta_motor = self.theta_load = theta
        # DC bus: rectified mains through a source resistance into the capacitor, braking chopper above its
        # threshold
        voltage = self.dc_bus
        power = 1.5 * (v_d * i_d + v_q * i_q)
        load_current = power / voltage if voltage > 1.0 else 0.0
        settled = plant.dc_bus_voltage - plant.supply_resistance * load_current
        if self.mains_on and settled <= plant.dc_bus_voltage:
            voltage = settled + (voltage - settled) * self._bus_decay
        else:
            voltage -= load_current * dt / plant.dc_bus_capacitance
        self.braking_power = 0.0
        if voltage > plant.braking_on_voltage:
            chopper = voltage / plant.braking_resistance
            self.braking_power = chopper * voltage
            voltage -= chopper * dt / plant.dc_bus_capacitance
        self.dc_bus = max(voltage, 0.0)
        copper = self._copper_factor * (i_d * i_d + i_q * i_q)
        target = plant.ambient_temperature + plant.thermal_resistance * copper
        self.temperature += (target - self.temperature) * dt / plant.thermal_time_constant
        # index pulse: latch the exact position of one crossed during this period
        cycle = math.floor(self.theta_motor / TWO_PI - plant.index_position)
        if cycle != self._index_cycle:
            boundary = max(cycle, self._index_cycle)
            self.index_turns = boundary + plant.index_position
            self.index_seen = True
            self._index_cycle = cycle

    def _step_two_mass(self, torque: float, dt: float) -> None:
        plant = self.plant
        spring = plant.coupling_stiffness * (self.theta_motor - self.theta_load) + plant.coupling_damping * (
            self.omega_motor - self.omega_load
        )
        self.omega_motor = self._brake(
            self.omega_motor,
            torque - spring - plant.viscous_friction * 0.1 * self.omega_motor,
            plant.motor_inertia,
            plant.coulomb_friction * 0.1,
            dt,
        )
        self.theta_motor += self.omega_motor * dt
        self.omega_load = _coulomb_step(
            self.omega_load,
            spring - plant.gravity_torque - plant.viscous_friction * 0.9 * self.omega_load,
            plant.load_inertia,
            plant.coulomb_friction * 0.9,
            dt,
        )
        self.theta_load += self.omega_load * dt
        self._hard_stops_load()

    def _brake(self, omega: float, driving: float, inertia: float, friction: float, dt: float) -> float:
        """An engaged holding brake adds its torque to the dry friction of the motor shaft."""
        if self.brake_engaged:
            friction += self.plant.brake_torque
        return _coulomb_step(omega, driving, inertia, friction, dt)

    def _hard_stops_load(self) -> None:
        low, high = self.plant.negative_hard_stop, self.plant.positive_hard_stop
        self.stopped_at_hard_stop = False
        if low is not None and self.theta_load <= low * TWO_PI and self.omega_load <= 0.0:
            self.theta_load = low * TWO_PI
            self.omega_load = 0.0
            self.stopped_at_hard_stop = True
        elif high is not None and self.theta_load >= high * TWO_PI and self.omega_load >= 0.0:
            self.theta_load = high * TWO_PI
            self.omega_load = 0.0
            self.stopped_at_hard_stop = True

    # -- switches -----------------------------------------------------------------------------------------------

    def negative_limit_active(self) -> bool:
        limit = self.plant.negative_limit_switch
        return limit is not None and self.load_turns <= limit

    def positive_limit_active(self) -> bool:
        limit = self.plant.positive_limit_switch
        return limit is not None and self.load_turns >= limit

    def home_switch_active(self) -> bool:
        window = self.plant.home_switch
        return window is not None and window[0] <= self.load_turns <= window[1]


def _coulomb_step(omega: float, driving: float, inertia: float, friction: float, dt: float) -> float:
    """Semi-implicit step with dry friction: the axis sticks while |driving torque| ≤ friction."""
    if omega == 0.0:
        if abs(driving) <= friction:
            return 0.0
        return dt * (driving - math.copysign(friction, driving)) / inertia
    new = omega + dt * (driving - math.copysign(friction, omega)) / inertia
    if (new > 0.0) != (omega > 0.0):
        return 0.0
    return new
