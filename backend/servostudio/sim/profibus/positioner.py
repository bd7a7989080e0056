"""The simulated TTA-PRO drive: its enabling state machine, the positioner, speed and torque modes, supervision
and monitors, on the shared plant, physics and loops (TTA-PRO Profibus Communication Profile, Chapter 2).

The enabling stages are the CiA 402 states of the shared `DeviceControl` (ENABLE inhibited = Switch On Disabled,
Ready for ENABLE = Ready To Switch On, Ready = Switched On, Operation enabled), driven by the TTA-PRO's own command
priority (`control_word`). The CiA 402 behaviour core itself is not shared: its control-word bits 4-15 are mode
bits, its parameters are object-dictionary entries with CiA units and it reports faults by EMCY; the TTA-PRO's
bits 4-14 are positioner commands, its units and parameters are PNUs, and its faults are polled (docs/profibus.md
§6).

The axis runs every control period (250 µs); commands, supervision and the status word every positioner cycle
(1 ms, L793).
"""

from __future__ import annotations

from servostudio.sim.clock import CONTROL_PERIOD
from servostudio.sim.drive.loops import MODE_POSITION
from servostudio.sim.drive.protection import I2tProtection
from servostudio.sim.drive.statemachine import (
    STATE_BITS,
    STOP_CURRENT_LIMIT,
    STOP_NONE,
    STOP_SLOW_DOWN_RAMP,
    Command,
    DeviceControl,
    Phase,
    State,
    StopOptions,
)
from servostudio.sim.plant import Plant
from servostudio.sim.profibus import control_word as cw
from servostudio.sim.profibus import pzd_image
from servostudio.sim.profibus.axis import Axis
from servostudio.sim.profibus.drive_units import FULL_SCALE, TWO_PI, DriveUnits, rating_code
from servostudio.sim.profibus.faults import BUS_ERROR, FOLLOWING_ERROR, I2T, WARNING_I2T, FaultRegister
from servostudio.sim.profibus.modes import MODES, POSITIONER, SPEED_MODES, TORQUE
from servostudio.sim.profibus.monitors import register_monitors
from servostudio.sim.profibus.motions import PositionerMotions
from servostudio.sim.profibus.parameters import LIMIT_EXCEEDED, NOT_IN_THIS_STATE, ParameterMemory, PkwRefusal
from servostudio.sim.profibus.status_word import status_word

CYCLE_PERIODS = 4
"""Control periods per positioner cycle."""
CYCLE = CYCLE_PERIODS * CONTROL_PERIOD
SOFTWARE_VERSION = 0x00052B68
"""PNU 770 of firmware 52B.68, the release the manual describes (L6)."""
PROFIBUS_VERSION = 0x0301
STOP_WITH_CURRENT_LIMIT = 1 << 10
"""PNU 842 bit 10: ENABLE loss and fault reactions brake at the stop current limit (705) before disabling."""
PROFIBUS_COMMAND = 1
"""PNU 843: the speed / torque command comes from PZD2 (0 = the analog input)."""


class TtaProDrive:
    def __init__(self, memory: ParameterMemory, plant: Plant, faults: FaultRegister, commission: bool = True) -> None:
        self.memory = memory
        self.plant = plant
        self.faults = faults
        self.axis = Axis(plant, CONTROL_PERIOD)
        self.units = DriveUnits(memory)
        self.device = DeviceControl()
        self.motions = PositionerMotions(self.axis, self.units, memory)
        self.i2t = I2tProtection(CYCLE)
        self.edges = cw.Edges()
        self.words: tuple[int, ...] = (0, 0)
        """PZD1.. of the PPO write last applied."""
        self.profibus_control = False
        self.enable_input = True
        self.powered = False
        self.mode = POSITIONER
        self.limit_switch = False
        self.software_limit = False
        self.following_error = False
        self.speed_target = 0.0
        """rad/s the speed mode is commanded to (what "speed reached" compares with)."""
        self._stop: int | None = None
        if commission:
            self._commission()
        self._set_identity()
        self._register_hooks()
        register_monitors(self)
        self.device.initialised()

    # -- set-up -------------------------------------------------------------------------------------------------

    def _commission(self) -> None:
        """A new drive is set up for its plant (the loops always are, see `axis`), and that set is saved."""
        plant, memory = self.plant, self.memory
        memory.set(715, rating_code(plant.peak_current))
        rating = self.units.rating
        memory.set(700, plant.pole_pairs)
        memory.set(701, plant.phase_order)
        memory.set(702, plant.sensor_offset)
        memory.set(710, max(6553, min(FULL_SCALE, round(plant.peak_current / rating * FULL_SCALE))))
        memory.set(711, max(6553, min(16384, round(plant.stall_current / rating * FULL_SCALE))))
        memory.set(721, plant.max_speed_rpm)
        memory.set(870, memory.get(740) or 65536)
        memory.save_eeprom()

    def _set_identity(self) -> None:
        """What the hardware reports whatever the EEPROM holds: rating, firmware versions."""
        self.memory.set(715, rating_code(self.plant.peak_current))
        self.memory.set(770, SOFTWARE_VERSION)
        self.memory.set(771, PROFIBUS_VERSION)

    def _register_hooks(self) -> None:
        memory = self.memory
        for pnu, parameter in memory.parameters.items():
            if parameter.disabled_only and not parameter.procedure:
                memory.on_write(pnu, self._only_disabled)
        memory.on_write(720, _check_mode)
        memory.on_write(740, lambda _, value: memory.set(870, value or 65536))
        memory.on_write(870, lambda _, value: memory.set(740, value if value < 65536 else 0))
        memory.on_write(pzd_image.FEEDBACK_MAPPING, _check_code(pzd_image.FEEDBACK_CODES))
        memory.on_write(pzd_image.COMMAND_MAPPING, _check_code(pzd_image.COMMAND_CODES))

    def _only_disabled(self, index: int, value: int) -> None:
        if self.powered:
            raise PkwRefusal(NOT_IN_THIS_STATE, "only with the positioner disabled")

    # -- PZD ----------------------------------------------------------------------------------------------------

    def receive(self, words: tuple[int, ...]) -> None:
        """PZD1.. of a PPO write (applied at the next positioner cycle)."""
        self.words = words

    def feedback(self, count: int) -> list[int]:
        """PZD1..count of the PPO read."""
        words = [status_word(self), self._feedback_word()] + [0] * max(0, count - 2)
        mapped = words[2:]
        for signal in pzd_image.layout(self._codes(pzd_image.FEEDBACK_MAPPING)):
            pzd_image.write_signal(mapped, signal, self.memory.read(signal.pnu, 0))
        return (words[:2] + mapped)[:count]

    def _feedback_word(self) -> int:
        if self.mode == POSITIONER:
            return (self.memory.get(743) & 0xFF) << 8 | 0xFF
        return self.memory.read(777 if self.mode == TORQUE else 776, 0) & 0xFFFF

    def _codes(self, pnu: int) -> list[int]:
        return [self.memory.get(pnu, slot) for slot in pzd_image.SLOTS]

    def _apply_commands(self) -> None:
        words = self.words
        if self.mode in SPEED_MODES:
            self.memory.set(707, _signed(words[1]))
        elif self.mode == TORQUE:
            self.memory.set(708, _signed(words[1]))
        for signal in pzd_image.layout(self._codes(pzd_image.COMMAND_MAPPING)):
            parameter = self.memory.parameters[signal.pnu]
            value = pzd_image.read_signal(words[2:], signal, parameter.data_type.is_signed)
            if value is not None:
                self.memory.set(signal.pnu, _clamped(value, parameter.low, parameter.high))

    # -- time -------------------------------------------------------------------------------------------------

    def step(self) -> None:
        """One control period."""
        self.axis.step(self.device.brake_released)

    def cycle(self) -> None:
        """One positioner cycle."""
        self._apply_commands()
        control = self.words[0]
        self.edges.update(control)
        self._control(control)
        self._supervise()

    def link_lost(self) -> None:
        """The DP watchdog expired: the outputs drop to 0, and a drive that PROFIBUS enabled trips on error 13."""
        if self.powered and self.profibus_control:
            self.faults.raise_fault(BUS_ERROR)
        self.words = (0,) * len(self.words)

    # -- enabling -----------------------------------------------------------------------------------------------

    def _control(self, control: int) -> None:
        if not self.powered:
            self.profibus_control = bool(control & cw.PROFIBUS_CONTROL)
            self.mode = self.memory.get(720)
        if self.edges.rising & cw.FAULT_ACKNOWLEDGE:
            self._acknowledge_faults()
        self._drive_state_machine(control)
        self.device.step(CYCLE)
        self._follow_power()
        if self.device.phase is Phase.STOPPING:
            self._run_stop()
        elif self.device.follows_set_points:
            self._run_mode(control)

    def _drive_state_machine(self, control: int) -> None:
        """A fault, the loss of the ENABLE input, or else the control word's command."""
        emergency_stop = STOP_CURRENT_LIMIT if self._brakes_on_fault() else STOP_NONE
        if self.faults.faulted:
            self.device.fault(emergency_stop)
        elif not self.enable_input and self.device.state is State.OPERATION_ENABLED:
            self.device.inhibit(emergency_stop)
        else:
            self.device.command(self._command(control), self._stop_options())

    def _command(self, control: int) -> Command:
        if not self.profibus_control:
            return Command.DISABLE_VOLTAGE
        command = cw.enabling_command(control)
        if not self.enable_input and command in (Command.SWITCH_ON, Command.ENABLE_OPERATION):
            return Command.SHUTDOWN
        return command

    def _stop_options(self) -> StopOptions:
        """The enabling stops, with the brake delays: 727 from enabling to brake release, 726 from brake
        engagement to disabling."""
        return StopOptions(
            quick_stop=STOP_CURRENT_LIMIT,
            shutdown=STOP_SLOW_DOWN_RAMP,
            disable_operation=STOP_SLOW_DOWN_RAMP,
            drive_reaction_time=self.memory.get(727) / 1000.0,
            brake_reaction_time=self.memory.get(726) / 1000.0,
        )

    def _brakes_on_fault(self) -> bool:
        return bool(self.memory.get(842) & STOP_WITH_CURRENT_LIMIT)

    def _acknowledge_faults(self) -> None:
        self.faults.acknowledge()
        self.motions.homing_failed = False
        self.following_error = False
        self.device.fault_reset()

    def _follow_power(self) -> None:
        on = self.device.power_on
        if on and not self.powered:
            self.axis.power_on()
            self.i2t.reset()
        elif not on and self.powered:
            self.axis.power_off()
            self.motions.cancel()
        self.powered = on

    # -- stops and modes ----------------------------------------------------------------------------------------

    def _run_stop(self) -> None:
        kind = self.device.stop_type
        if self._stop != kind:
            self._stop = kind
            self.motions.cancel()
            if kind != STOP_SLOW_DOWN_RAMP:
                self.axis.brake_at_limit()
            elif self.mode == POSITIONER:
                self.axis.ramp_stop(self.units.ramp(self.memory.get(765)))
        if kind == STOP_SLOW_DOWN_RAMP and self.mode != POSITIONER:
            ramp = self.units.ramp(self.memory.get(723) * 0.5)
            self.axis.run_velocity(0.0, ramp, ramp)
        if self._stop_done(kind):
            self._stop = None
            self.device.stop_finished(self._stop_options())

    def _stop_done(self, kind: int) -> bool:
        if kind != STOP_SLOW_DOWN_RAMP:
            return not self.axis.braking
        return self.axis.stopped if self.mode != POSITIONER else not self.axis.moving

    def _run_mode(self, control: int) -> None:
        if self.mode == POSITIONER:
            self.motions.run(control, self.edges.toggled, self.edges.rising)
        elif self.mode == TORQUE:
            self.axis.run_current(self.units.direction * self._command_share(708) * self.units.rating)
        else:
            ramp = self.units.ramp(self.memory.get(723) * 0.5)
            self.speed_target = self.units.direction * self._command_share(707) * self.units.max_speed
            self.axis.run_velocity(self.speed_target, ramp, ramp)

    def _command_share(self, pnu: int) -> float:
        """The PZD2 command (or the analog input, PNU 843 = 0) as a share of its full scale."""
        source = pnu if self.memory.get(843) == PROFIBUS_COMMAND else 818
        return self.memory.get(source) / FULL_SCALE

    # -- supervision --------------------------------------------------------------------------------------------

    def _supervise(self) -> None:
        self._limit_switches()
        self._software_limits()
        self._following_error()
        self._i2t()
        self.axis.loops.current_limit = self._current_limit()
        if self.motions.homing_failed:
            self.faults.raise_fault(4)

    def _limit_switches(self) -> None:
        physics = self.axis.physics
        velocity = self.axis.profile.velocity if self.axis.moving else self.axis.speed
        positive, negative = physics.positive_limit_active(), physics.negative_limit_active()
        self.limit_switch = positive or negative
        homing = self.motions.active == "homing"
        if self.powered and not homing and ((positive and velocity > 0) or (negative and velocity < 0)):
            self.motions.cancel()
            self.axis.brake_at_limit()

    def _software_limits(self) -> None:
        configuration = self.memory.get(742)
        position = self.units.position(self.axis.position)
        above = bool(configuration & 1) and position >= self.memory.get(747)
        below = bool(configuration & 2) and position <= self.memory.get(748)
        self.software_limit = above or below
        velocity = self.units.direction * self.axis.profile.velocity
        if self.powered and ((above and velocity > 0) or (below and velocity < 0)):
            self.motions.cancel()
            self.axis.brake_at_limit()

    def _following_error(self) -> None:
        loops = self.axis.loops
        if not self.powered or self.axis.braking or loops.mode != MODE_POSITION:
            return
        error = abs(loops.position_ref - loops.position) / TWO_PI * self.units.increments_per_turn
        if error > self.memory.get(741):
            self.following_error = True
            self.faults.raise_fault(FOLLOWING_ERROR)

    def _i2t(self) -> None:
        loops = self.axis.loops
        electrical_hz = self.plant.pole_pairs * loops.speed / TWO_PI
        fusing = self.i2t.step(abs(loops.i_q), self.units.rated_current, electrical_hz)
        if fusing and self.memory.get(712) == 1:
            self.faults.raise_fault(I2T)
        self.faults.warnings = (self.faults.warnings & ~WARNING_I2T) | (WARNING_I2T if self.i2t.warning else 0)

    def _current_limit(self) -> float:
        limit = self.units.max_current * self.memory.get(713) / FULL_SCALE
        if self.i2t.limiting:
            limit = min(limit, self.units.rated_current)
        if self.device.stop_type == STOP_CURRENT_LIMIT and self._brakes_on_fault():
            limit = min(limit, self.units.max_current * self.memory.get(705) / FULL_SCALE)
        return max(limit, 0.0)

    @property
    def state_bits(self) -> int:
        """Status bits 0-3 and 6 of the present state (bit 5 is the TTA-PRO's own "no OFF3")."""
        return STATE_BITS[self.device.state] & 0x4F


def _check_mode(index: int, value: int) -> None:
    if value not in MODES:
        raise PkwRefusal(LIMIT_EXCEEDED, f"positioner mode {value} is not one of 1, 2, 4, 8, 16")


def _check_code(codes: frozenset[int]):
    def check(index: int, value: int) -> None:
        if value not in codes:
            raise PkwRefusal(LIMIT_EXCEEDED, f"0x{value:04X} is not a signal code of this mapping")

    return check


def _signed(word: int) -> int:
    return word - 0x10000 if word & 0x8000 else word


def _clamped(value: int, low: int | None, high: int | None) -> int:
    if low is not None:
        value = max(value, low)
    return min(value, high) if high is not None else value
