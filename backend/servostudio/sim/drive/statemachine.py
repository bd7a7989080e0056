"""CiA 402 device control as the XtrapulsPac manual describes it (§3.2.1.1–3.2.1.6): states, commands, option
codes, stop sequences and brake timing.

The class decides *what* happens (state, power stage, brake, which stop runs); the behaviour carries the stop
out with its loops and reports back when the motor stands still.

Timing (manual §3.2.2.2, reconstructed): on Enable Operation the power stage comes on at once, the brake is
released after the drive reaction time 0x3304 and the state shows Operation Enabled after a further 0x3305
(brake reaction time). On a commanded disable the motor is held while the brake engages for 0x3305, then the
power stage switches off. Disable Voltage and Stop 0 fault reactions switch off at once (brake applied).
"""

from __future__ import annotations

import enum
from dataclasses import dataclass


class State(enum.Enum):
    NOT_READY_TO_SWITCH_ON = "NOT READY TO SWITCH ON"
    SWITCH_ON_DISABLED = "SWITCH ON DISABLED"
    READY_TO_SWITCH_ON = "READY TO SWITCH ON"
    SWITCHED_ON = "SWITCHED ON"
    OPERATION_ENABLED = "OPERATION ENABLED"
    QUICK_STOP_ACTIVE = "QUICK STOP ACTIVE"
    FAULT_REACTION_ACTIVE = "FAULT REACTION ACTIVE"
    FAULT = "FAULT"


STATE_BITS = {
    State.NOT_READY_TO_SWITCH_ON: 0x0000,
    State.SWITCH_ON_DISABLED: 0x0040,
    State.READY_TO_SWITCH_ON: 0x0021,
    State.SWITCHED_ON: 0x0023,
    State.OPERATION_ENABLED: 0x0027,
    State.QUICK_STOP_ACTIVE: 0x0007,
    State.FAULT_REACTION_ACTIVE: 0x000F,
    State.FAULT: 0x0008,
}
"""Status word bits 0–6 per state (bit 4 "voltage enabled" stays 0, as in the manual's examples)."""


class Command(enum.Enum):
    SHUTDOWN = "shutdown"
    SWITCH_ON = "switch on"  # also "disable operation" in Operation Enabled
    ENABLE_OPERATION = "enable operation"
    DISABLE_VOLTAGE = "disable voltage"
    QUICK_STOP = "quick stop"


def decode_command(control_word: int) -> Command:
    """Bits 3..0 of the control word (manual §3.2.1.2 command table)."""
    if not control_word & 0x02:
        return Command.DISABLE_VOLTAGE
    if not control_word & 0x04:
        return Command.QUICK_STOP
    if not control_word & 0x01:
        return Command.SHUTDOWN
    if control_word & 0x08:
        return Command.ENABLE_OPERATION
    return Command.SWITCH_ON


STOP_NONE = 0
STOP_SLOW_DOWN_RAMP = 1  # Stop 1: position loop, ramp 0x3300,1 from the reference speed
STOP_QUICK_STOP_RAMP = 2  # Stop 2: speed loop, ramp 0x6085 from the actual speed
STOP_CURRENT_LIMIT = 3  # Stop 3: speed loop, zero speed at the current limit 0x3301,1


@dataclass
class StopOptions:
    """Option codes and brake times, refreshed by the behaviour from the object store."""

    quick_stop: int = 1
    shutdown: int = 0
    disable_operation: int = 1
    drive_reaction_time: float = 0.0
    brake_reaction_time: float = 0.0


class Phase(enum.Enum):
    IDLE = "idle"
    ENABLING = "enabling"
    STOPPING = "stopping"
    BRAKING = "braking"


# Enum member lookups through the class are slow in the per-period path: plain module constants instead
_IDLE, _ENABLING, _BRAKING = Phase.IDLE, Phase.ENABLING, Phase.BRAKING
_OPERATION_ENABLED = State.OPERATION_ENABLED


class DeviceControl:
    """The state machine plus the power-stage/brake sequence that goes with each transition."""

    def __init__(self) -> None:
        self.state = State.NOT_READY_TO_SWITCH_ON
        self.power_on = False
        self.brake_released = False
        self.stop_type = STOP_NONE
        self.phase = Phase.IDLE
        self.transition = 0
        """Number of the last transition taken (manual §3.2.1.1), for tests and logs."""
        self._target = State.SWITCH_ON_DISABLED
        self._timer = 0.0
        self._enable_after_brake = 0.0
        self._release_at = 0.0
        self._pending = 0

    # -- queries ------------------------------------------------------------------------------------------------

    @property
    def follows_set_points(self) -> bool:
        """The operation mode drives the loops (not a stop, not enabling, not braking)."""
        return self.state is _OPERATION_ENABLED and self.phase is _IDLE

    # -- events -------------------------------------------------------------------------------------------------

    def initialised(self) -> None:
        """Transition 1: self-test done, communication active."""
        self._go(State.SWITCH_ON_DISABLED, 1)

    def command(self, command: Command, options: StopOptions, can_enable: bool = True) -> None:
        """Apply a control-word command. `can_enable` False refuses transition 4 (e.g. phasing not done)."""
        state = self.state
        if state in (State.FAULT, State.FAULT_REACTION_ACTIVE, State.NOT_READY_TO_SWITCH_ON):
            return
        if self.phase is Phase.STOPPING and state is State.OPERATION_ENABLED and command is not Command.DISABLE_VOLTAGE:
            return  # a commanded ramp stop runs to its end
        handler = {
            State.SWITCH_ON_DISABLED: self._from_switch_on_disabled,
            State.READY_TO_SWITCH_ON: self._from_ready,
            State.SWITCHED_ON: self._from_switched_on,
            State.OPERATION_ENABLED: self._from_operation_enabled,
            State.QUICK_STOP_ACTIVE: self._from_quick_stop,
        }[state]
        handler(command, options, can_enable)

    def fault(self, stop_type: int) -> None:
        """Transition 13: any state → Fault Reaction Active; Stop 0 ends in Fault at once (transition 14)."""
        if self.state in (State.FAULT, State.FAULT_REACTION_ACTIVE):
            return
        was_powered = self.power_on and self.brake_released
        self._go(State.FAULT_REACTION_ACTIVE, 13)
        if was_powered and stop_type in (STOP_SLOW_DOWN_RAMP, STOP_QUICK_STOP_RAMP, STOP_CURRENT_LIMIT):
            self._start_stop(stop_type, State.FAULT)
        else:
            self._switch_off(State.FAULT, 14)

    def inhibit(self, code: int) -> None:
        """INHIBIT input: 0x305A 0 switches off at once, 1/2/3 ramp / quick-stop ramp / current limit first;
        the drive ends in Switch On Disabled."""
        if self.state is not State.OPERATION_ENABLED and self.state is not State.QUICK_STOP_ACTIVE:
            if self.state in (State.SWITCHED_ON, State.READY_TO_SWITCH_ON):
                self._switch_off(State.SWITCH_ON_DISABLED, 10 if self.state is State.SWITCHED_ON else 7)
            return
        if code in (1, 2, 3) and self.power_on and self.brake_released:
            self._start_stop(code, State.SWITCH_ON_DISABLED)
        else:
            self._switch_off(State.SWITCH_ON_DISABLED, 9)

    def fault_reset(self) -> bool:
        """Transition 15 (the caller checked that no error is still present)."""
        if self.state is not State.FAULT:
            return False
        self._go(State.SWITCH_ON_DISABLED, 15)
        return True

    def stop_finished(self, options: StopOptions) -> None:
        """The behaviour reports standstill (or gave up): brake, then the target state."""
        if self.phase is not Phase.STOPPING:
            return
        self.stop_type = STOP_NONE
        if self._target is State.QUICK_STOP_ACTIVE:
            self.phase = Phase.IDLE  # codes 5–7: stay in quick stop, holding
            return
        if self._target is State.FAULT:
            self._switch_off(State.FAULT, 14)
            return
        self.transition = self._pending
        self._begin_braking(self._target, options)

    def step(self, dt: float) -> None:
        """Advance the enable and brake timers."""
        phase = self.phase
        if phase is _IDLE:
            return
        if phase is _ENABLING:
            self._timer += dt
            if self._timer >= self._release_at:
                self.brake_released = True
            if self._timer >= self._enable_after_brake:
                self.phase = Phase.IDLE
                self._go(State.OPERATION_ENABLED, 4)
        elif phase is _BRAKING:
            self._timer -= dt
            if self._timer <= 0.0:
                self._switch_off(self._target, self.transition)

    # -- transitions --------------------------------------------------------------------------------------------

    def _from_switch_on_disabled(self, command: Command, options: StopOptions, can_enable: bool) -> None:
        if command is Command.SHUTDOWN:
            self._go(State.READY_TO_SWITCH_ON, 2)

    def _from_ready(self, command: Command, options: StopOptions, can_enable: bool) -> None:
        if command in (Command.DISABLE_VOLTAGE, Command.QUICK_STOP):
            self._go(State.SWITCH_ON_DISABLED, 7)
        elif command is Command.SWITCH_ON:
            self._go(State.SWITCHED_ON, 3)
        elif command is Command.ENABLE_OPERATION:
            self._go(State.SWITCHED_ON, 3)
            self._from_switched_on(command, options, can_enable)

    def _from_switched_on(self, command: Command, options: StopOptions, can_enable: bool) -> None:
        if command in (Command.DISABLE_VOLTAGE, Command.QUICK_STOP):
            self._switch_off(State.SWITCH_ON_DISABLED, 10)
        elif command is Command.SHUTDOWN:
            self._switch_off(State.READY_TO_SWITCH_ON, 6)
        elif command is Command.ENABLE_OPERATION and can_enable and self.phase is Phase.IDLE:
            self.power_on = True
            self.phase = Phase.ENABLING
            self._timer = 0.0
            self._release_at = options.drive_reaction_time
            self._enable_after_brake = options.drive_reaction_time + options.brake_reaction_time
            self.step(0.0)

    def _from_operation_enabled(self, command: Command, options: StopOptions, can_enable: bool) -> None:
        if command is Command.DISABLE_VOLTAGE:
            self._switch_off(State.SWITCH_ON_DISABLED, 9)
        elif command is Command.QUICK_STOP:
            self._go(State.QUICK_STOP_ACTIVE, 11)
            code = options.quick_stop
            ramp = code - 4 if code in (5, 6, 7) else code
            target = State.QUICK_STOP_ACTIVE if code in (5, 6, 7) else State.SWITCH_ON_DISABLED
            if ramp in (1, 2, 3):
                self._start_stop(ramp, target)
            elif target is State.QUICK_STOP_ACTIVE:
                self.phase = Phase.IDLE
            else:
                self._switch_off(State.SWITCH_ON_DISABLED, 12)
        elif command is Command.SHUTDOWN:
            self._leave_operation(options.shutdown, State.READY_TO_SWITCH_ON, 8, options)
        elif command is Command.SWITCH_ON:
            self._leave_operation(options.disable_operation, State.SWITCHED_ON, 5, options)

    def _from_quick_stop(self, command: Command, options: StopOptions, can_enable: bool) -> None:
        if command is Command.DISABLE_VOLTAGE:
            self.stop_type = STOP_NONE
            self._switch_off(State.SWITCH_ON_DISABLED, 12)
        elif command is Command.ENABLE_OPERATION and options.quick_stop in (5, 6, 7, 8) and self.phase is Phase.IDLE:
            self._go(State.OPERATION_ENABLED, 16)

    def _leave_operation(self, code: int, target: State, transition: int, options: StopOptions) -> None:
        self.transition = transition
        if code in (1, 2, 3):
            self._start_stop(code, target)
        elif transition == 8:
            self._switch_off(target, transition)  # shutdown code 0: power off immediately
        else:
            self._begin_braking(target, options)

    def _start_stop(self, stop_type: int, target: State) -> None:
        self.stop_type = stop_type
        self.phase = Phase.STOPPING
        self._target = target
        self._pending = {State.SWITCH_ON_DISABLED: 12, State.FAULT: 14}.get(target, self.transition)

    def _begin_braking(self, target: State, options: StopOptions) -> None:
        self.brake_released = False
        self.phase = Phase.BRAKING
        self._target = target
        self._timer = options.brake_reaction_time
        if self._timer <= 0.0:
            self._switch_off(target, self.transition)

    def _switch_off(self, target: State, transition: int) -> None:
        self.power_on = False
        self.brake_released = False
        self.stop_type = STOP_NONE
        self.phase = Phase.IDLE
        self._go(target, transition)

    def _go(self, state: State, transition: int) -> None:
        self.state = state
        self.transition = transition
