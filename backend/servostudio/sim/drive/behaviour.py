"""The simulated drive: CiA 402 device control, operation modes, loops, physics, protections and procedures,
bound to one node's `ObjectStore` (docs/simulator.md, docs/control-loops.md).

Each control period (`step`) the drive reads its control word, runs the state machine and the active mode's
set-point generator, checks its protections, runs the loops and the physics, and publishes its measurements;
last, an armed oscilloscope recorder (docs/scope.md) samples the period's values. Parameters (gains, limits,
option codes) are re-read every 32 ms and right after any bus write to them; protections, inputs and the status
word run every 1 ms; measurements are computed when the bus reads them.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any, Protocol

from servostudio.sim.clock import CONTROL_PERIOD
from servostudio.sim.drive import errors, gains
from servostudio.sim.drive.commissioning import commissioned_values, current_limits
from servostudio.sim.drive.device_map import (
    MODE_HM,
    MODE_IP,
    MODE_PP,
    MODE_PT,
    MODE_PV,
    MODE_SQ,
    XTRAPULSPAC,
    DeviceProfile,
)
from servostudio.sim.drive.errors import DriveError
from servostudio.sim.drive.loops import (
    MODE_OFF,
    MODE_POSITION,
    MODE_VELOCITY,
    ServoLoops,
    low_pass_alpha,
    time_constant_alpha,
)
from servostudio.sim.drive.modes import (
    BIT_TARGET_REACHED,
    CW_HALT,
    U32_OFF,
    HomingMode,
    InterpolatedPosition,
    ModeHandler,
    ProfilePosition,
    ProfileTorque,
    ProfileVelocity,
)
from servostudio.sim.drive.outputs import LogicOutputs
from servostudio.sim.drive.physics import OVERCURRENT_FACTOR, TWO_PI, AxisPhysics
from servostudio.sim.drive.procedures import ABORTED, FAILED
from servostudio.sim.drive.protection import I2tProtection
from servostudio.sim.drive.recorder import Recorder
from servostudio.sim.drive.runner import ProcedureRunner
from servostudio.sim.drive.sequencer import SequenceMode
from servostudio.sim.drive.statemachine import (
    STATE_BITS,
    STOP_CURRENT_LIMIT,
    STOP_QUICK_STOP_RAMP,
    STOP_SLOW_DOWN_RAMP,
    Command,
    DeviceControl,
    Phase,
    State,
    StopOptions,
    decode_command,
)
from servostudio.sim.drive.units import RPM, UnitScaling
from servostudio.sim.objects import ObjectStore
from servostudio.sim.plant import FEEDBACK_ENCODER, PHASE_240, Plant

REMOTE = 1 << 9
WARNING = 1 << 7
BUSY = 1 << 15
CW_FAULT_RESET = 1 << 7
PARAMETER_REFRESH_PERIODS = 128
SUPERVISION_PERIODS = 4
SLOW_PUBLISH_PERIODS = 32
STANDSTILL_SPEED = 0.5  # rad/s: a stop has ended below this speed
#: 0x60FD: the input functions (bits 0–15: limit switches, home, INHIBIT, …) and the INHIBIT bit
INPUT_FUNCTIONS, INPUT_INHIBIT, INPUT_RESET, INPUT_QUICK_STOP = 0xFFFF, 1 << 3, 1 << 12, 1 << 15
DEFAULT_DRIVE_RATED_CURRENT = 5.0
"""A, the smallest drive rating the simulated drives have (a larger motor gets a drive rated for its stall current)."""
UNDERVOLTAGE_DEFAULTS = {400: 210, 230: 100, 48: 30, 34: 20, 17: 17}
"""XtrapulsPac operating voltage (Vac) → undervoltage threshold default 0x6510,5 (V), manual §0x6510."""


def supply_class(dc_bus_voltage: float) -> int:
    """The operating voltage class (Vac) whose rectified peak is nearest to the DC bus voltage."""
    return min(UNDERVOLTAGE_DEFAULTS, key=lambda vac: abs(vac * math.sqrt(2.0) - dc_bus_voltage))


_STOPPING = Phase.STOPPING
_IDLE = Phase.IDLE


class Events(Protocol):
    """What the node gives the drive (servostudio.sim.events.DriveEvents)."""

    def emergency(self, error_code: int, infranor_code: int = 0, manufacturer: bytes = b"") -> None: ...
    def emergency_cleared(self) -> None: ...


class DriveBehaviour:
    """CiA 402 drive on the shared engine; device families differ by `DeviceProfile` and small overrides."""

    def __init__(
        self, store: ObjectStore, plant: Plant, events: Events, commissioned: bool, profile: DeviceProfile = XTRAPULSPAC
    ) -> None:
        self.store = store
        self.plant = plant
        self.events = events
        self.commissioned = commissioned
        self.profile = profile
        self.dt = CONTROL_PERIOD
        self.time = 0.0
        self.physics = AxisPhysics(plant, self.dt)
        self.loops = ServoLoops(self.physics)
        self.device_control = DeviceControl()
        self.i2t = I2tProtection(self.dt * SUPERVISION_PERIODS)
        self.units = UnitScaling()
        self.handlers: dict[int, ModeHandler] = {
            MODE_PP: ProfilePosition(self),
            MODE_PV: ProfileVelocity(self),
            MODE_PT: ProfileTorque(self),
            MODE_HM: HomingMode(self),
            MODE_IP: InterpolatedPosition(self),
        }
        self.active_mode = 0
        self.control_word = 0
        self.halted = False  # control word bit 8 on a device that has the halt bit
        self.active_errors: dict[int, DriveError] = {}
        self.warnings = 0
        self.following_error_active = False
        self.temperature_warning = False
        self.inhibit_active = False
        self.negative_limit = self.positive_limit = self.home_switch = False
        #: 0x60FD function bits (0–15) the logic inputs give through their configuration (``sequencer/inputs.py``)
        self.routed_inputs = 0
        self._routed_inhibit = False
        self._input_levels = 0  # 0x60FD functions at the last supervision: RESET and QUICK STOP act on edges
        self.quick_stop_input = False
        self.position_offset_user = 0.0
        self.phasing_valid = plant.feedback != FEEDBACK_ENCODER  # an incremental encoder needs 'mcal' first
        self.max_speed = 1.0
        self.rated_current = 1.0
        self.max_current = 1.0
        self.drive_max_current = 1.0
        self._addresses = {name: addr for name, addr in profile.objects.items() if addr in store}
        self._read_control_word = store.integer_reader(*profile.objects["control_word"])
        self._active_handler: ModeHandler | None = None
        self._linked_bits = 0
        self.p: dict[str, Any] = {}
        self.snapshot()
        self._stop_options = StopOptions()
        self._stop_time = 0.0
        self._stop_ramp_velocity = 0.0
        self._hold_position = 0.0
        self._following_time = 0.0
        self._periods = 0
        self._dirty = True
        self._published_status = -1
        self._published_state: State | None = None
        self._published_inputs = -1
        self._current_filter = 0.0
        self._current_filter_alpha = 1.0
        self._velocity_filter = 0.0
        self._velocity_filter_alpha = 1.0
        self._measure = self._measurement_functions()
        self.set_hardware_data()
        if commissioned:
            self.apply_commissioning()
        self._register_hooks()
        self.procedures = ProcedureRunner(self)
        self.recorder = Recorder.for_store(store)
        self.outputs = LogicOutputs(store)
        self.sequencer = SequenceMode.for_drive(self)
        if self.sequencer is not None:
            self.handlers[MODE_SQ] = self.sequencer
        self.write("supported_modes", profile.supported_modes_word)
        self.refresh_parameters()
        self.device_control.initialised()
        self._publish_all()

    # -- object access ------------------------------------------------------------------------------------------

    def has(self, name: str) -> bool:
        return name in self._addresses

    def read(self, name: str, default: Any = 0) -> Any:
        """Value from the parameter snapshot (taken every 32 ms and right after any bus write)."""
        return self.p.get(name, default)

    def write(self, name: str, value: float, integer: bool = False) -> None:
        address = self._addresses.get(name)
        if address is not None:
            if integer:
                value = _wrap_i32(value)
            self.store.set(address[0], address[1], value)
            self.p[name] = value

    def live(self, name: str, default: Any = 0) -> Any:
        """Value straight from the store (inputs of a hook or procedure, written moments ago)."""
        address = self._addresses.get(name)
        return default if address is None else self.store.get(*address)

    def snapshot(self) -> None:
        self.p = self.store.values_by_name(self._addresses)

    def pointer_reader(self, source_name: str, default_name: str) -> Callable[[], float]:
        """A reader of a "dataflow" source object (index<<16 | sub<<8): what it points to, else the default
        object. Valid until the next parameter snapshot (mode handlers take one in `configure`)."""
        pointer = self.p.get(source_name, 0)
        if pointer:
            address = ((pointer >> 16) & 0xFFFF, (pointer >> 8) & 0xFF)
            if address in self.store:
                read = self.store.reader(*address)
                return lambda: float(read())
        parameters = self.p
        return lambda: float(parameters.get(default_name, 0))

    # -- hooks --------------------------------------------------------------------------------------------------

    def _register_hooks(self) -> None:
        store = self.store
        for index in sorted({address[0] for address in self._addresses.values()}):
            store.on_write(index, None, self._mark_dirty)
        for name in (
            "motor_max_speed",
            "motor_stall_current",
            "motor_peak_current",
            "motor_inductance",
            "motor_pole_pairs",
            "motor_phase",
            "motor_offset",
        ):
            address = self._addresses.get(name)
            if address is not None:
                store.on_write(address[0], address[1], self._motor_data_written(name))
        if (0x6410, 6) in store and (0x6402, 0) in store:
            store.on_write(0x6410, 6, lambda i, s, v: store.set(0x6402, 0, v))
        for sub in range(21, 26):
            if (0x6410, sub) in store and (0x3420, sub - 20) in store:
                store.on_write(0x6410, sub, lambda i, s, v: store.set(0x3420, s - 20, v))
        for name in (
            "position_actual",
            "velocity_actual",
            "position_demand",
            "following_error_actual",
            "current_actual",
        ):
            address = self._addresses.get(name)
            if address is not None:
                store.on_read(address[0], address[1], self._measurement_reader(name))
        for name in ("control_offset", "control_pole_pairs", "control_phase"):
            address = self._addresses.get(name)
            if address is not None:
                store.on_write(address[0], address[1], self._phasing_entered)

    def _mark_dirty(self, index: int, sub: int, value: Any) -> None:
        self._dirty = True

    def _phasing_entered(self, index: int, sub: int, value: Any) -> None:
        """Commutation values entered by hand count as a done phasing (the user takes responsibility)."""
        self.phasing_valid = True

    def _motor_data_written(self, name: str):
        """0x6410 copy rules (manual §3.2.2.1): max speed → 0x6080, inductance → 0x340F, pole pairs/phase/offset →
        0x3410, stall/peak current → the 0x3412 limits."""
        copies = {
            "motor_max_speed": "max_motor_speed",
            "motor_inductance": "control_inductance",
            "motor_pole_pairs": "control_pole_pairs",
            "motor_phase": "control_phase",
            "motor_offset": "control_offset",
        }

        def hook(index: int, sub: int, value: Any) -> None:
            if name in copies:
                self.write(copies[name], value)
                if name in ("motor_pole_pairs", "motor_phase", "motor_offset"):
                    self.phasing_valid = True
            if name in ("motor_stall_current", "motor_peak_current"):
                stall = value if name == "motor_stall_current" else self.live("motor_stall_current", 0)
                peak = value if name == "motor_peak_current" else self.live("motor_peak_current", 0)
                self.apply_current_limits(float(stall), float(peak))
            self._dirty = True

        return hook

    def apply_current_limits(self, stall_ma: float, peak_ma: float) -> None:
        rated, maximum = current_limits(
            stall_ma, peak_ma, float(self.live("drive_max_current", 0)), float(self.live("drive_rated_current", 0))
        )
        if rated:
            self.write("rated_current", rated)
            self.write("max_current", maximum)

    # -- commissioning ------------------------------------------------------------------------------------------

    def set_hardware_data(self) -> None:
        """Factory values of the drive's hardware where its dictionary gives no default: the node ID switches,
        current ratings sized for the plant's motor, the sensor's increments per revolution, and the supply voltage
        class of the plant's DC bus with the manual's undervoltage default for it."""
        rated = max(self.plant.stall_current, DEFAULT_DRIVE_RATED_CURRENT)
        voltage = supply_class(self.plant.dc_bus_voltage)
        values = {
            "device_id": self.store.node_id,
            "drive_max_current": round(max(self.plant.peak_current, rated) * 1000),
            "drive_rated_current": round(rated * 1000),
            "drive_voltage": 400 if voltage == 400 else 230,
            "operating_voltage": voltage,
            "undervoltage_threshold": UNDERVOLTAGE_DEFAULTS[voltage],
            "encoder_increments": self.physics.counts_per_turn,
        }
        for name, value in values.items():
            address = self._addresses.get(name)
            if address is None:
                continue
            variable = self.store.od[address]
            if variable.default_for(self.store.node_id) is None:
                self.store.set_factory(address[0], address[1], self._fit(variable, value))
        self.snapshot()

    def apply_commissioning(self) -> None:
        """Write the plant's true motor data, phasing and gains over the dictionary defaults."""
        values = commissioned_values(
            self.plant, float(self.p.get("drive_max_current", 0)), float(self.p.get("drive_rated_current", 0))
        )
        values["motor_phase"] = values["control_phase"] = self.phase_value(self.plant.phase_sign)
        for name, value in values.items():
            address = self._addresses.get(name)
            if address is None:
                continue
            variable = self.store.od[address]
            if self.store.get(*address) == self.store.factory_value(variable):
                self.store.set(address[0], address[1], self._fit(variable, value))

    @staticmethod
    def _fit(variable: Any, value: int) -> int:
        low, high = variable.minimum, variable.maximum
        if high is not None:
            value = min(value, high)
        if low is not None:
            value = max(value, low)
        return value

    # -- parameters ---------------------------------------------------------------------------------------------

    def refresh_parameters(self) -> None:
        """Snapshot the objects and convert the parameters into the loops' physical units."""
        self._dirty = False
        self.snapshot()
        read = self.p.get
        dt = self.dt
        loops = self.loops
        self.units = self.read_units()
        self.drive_max_current, self.rated_current, self.max_current = self.read_currents()
        rpm = float(read("max_motor_speed", 0))
        self.max_speed = rpm * RPM if rpm > 0 else 1e4
        loops.pole_pairs = int(read("control_pole_pairs", 1)) or 1
        loops.phase_sign = self.phase_sign_of(int(read("control_phase", PHASE_240)))
        loops.offset_turns = float(read("control_offset", 0)) / 65536.0
        loops.emf_constant = float(read("motor_torque_constant", 0)) * 1e-3 / 1.5
        loops.kp_q = float(read("kp_current_q", 0)) * gains.CURRENT_KP_UNIT
        loops.ki_q = float(read("ki_current_q", 0)) * gains.CURRENT_KI_UNIT
        loops.kp_d = float(read("kp_current_d", 0)) * gains.CURRENT_KP_UNIT
        loops.ki_d = float(read("ki_current_d", 0)) * gains.CURRENT_KI_UNIT
        kj = float(read("kj_speed", gains.KJV_ONE)) / gains.KJV_ONE
        loops.kpv = float(read("kp_speed", 0)) * gains.KPV_UNIT * kj
        loops.kiv = float(read("ki_speed", 0)) * gains.KIV_UNIT * kj
        loops.kcv = float(read("kc_speed", 0)) * gains.KPV_UNIT * kj
        loops.kbv = float(read("kb_position", 0)) * gains.KPV_UNIT * kj
        loops.kav = float(read("ka_position", 0)) * gains.KAV_UNIT * kj
        loops.kdv = float(read("kd_speed", 0)) * gains.KDV_UNIT
        loops.integral_leak = TWO_PI * float(read("ki_speed_filter", 0)) * gains.KIVF_UNIT_HZ
        kdvf = float(read("kd_speed_filter", 0))
        loops.derivative_alpha = low_pass_alpha(kdvf, dt) if kdvf > 0 else 1.0
        loops.kpp = float(read("kp_position", 0)) * gains.KPP_UNIT
        loops.kfp = float(read("kf_position", 0)) / gains.KFP_FULL
        loops.speed_alpha = time_constant_alpha(gains.SPEED_FILTER_TAU.get(int(read("speed_filter", 0)), 0.5e-3), dt)
        loops.command_alphas = tuple(
            low_pass_alpha(float(read(name, 0)), dt)
            for name in ("current_filter_1", "current_filter_2", "current_filter_3")
            if float(read(name, 0)) > 0
        )
        loops.torque_offset = float(read("torque_offset", 0)) / 1000.0 * self.rated_current
        loops.torque_offset_2 = float(read("torque_offset_2", 0)) / 1000.0 * self.rated_current
        supervision_dt = dt * SUPERVISION_PERIODS
        self._current_filter_alpha = low_pass_alpha(
            max(float(read("current_monitor_filter", 1000)), 1.0), supervision_dt
        )
        velocity_hz = float(read("velocity_monitor_filter", 0)) * 0.1
        self._velocity_filter_alpha = low_pass_alpha(velocity_hz, supervision_dt) if velocity_hz > 0 else 1.0
        options = self._stop_options
        options.quick_stop = int(read("quick_stop_code", 1))
        options.shutdown = int(read("shutdown_code", 0))
        options.disable_operation = int(read("disable_operation_code", 1))
        options.drive_reaction_time = float(read("drive_reaction_time", 0)) / 1000.0
        options.brake_reaction_time = float(read("brake_reaction_time", 0)) / 1000.0
        self._limit = self._base_current_limit()
        self._overcurrent_squared = (OVERCURRENT_FACTOR * self.drive_max_current) ** 2
        self._undervoltage = float(read("undervoltage_threshold", 0))
        self._fusing = int(read("i2t_mode", 1)) == 1
        mode = int(read("mode", self.profile.default_mode))
        if mode != self.active_mode:
            self._change_mode(mode)
        if self._active_handler is not None:
            self._active_handler.configure()

    def read_units(self) -> UnitScaling:
        """Factor group 0x6093 (XtrapulsPac: numerator fixed at 4096 motor increments per revolution)."""
        return UnitScaling.from_position_factor(
            int(self.p.get("position_factor_numerator", 4096)), int(self.p.get("position_factor_denominator", 4096))
        )

    def read_currents(self) -> tuple[float, float, float]:
        """(drive max, motor rated, max allowed) in A: 0x6510,1 mA, 0x6075 mA, 0x6073 ‰ of 0x6075."""
        drive_max = float(self.p.get("drive_max_current", 0)) / 1000.0 or self.plant.peak_current
        rated = float(self.p.get("rated_current", 0)) / 1000.0
        if rated <= 0:
            rated = float(self.p.get("drive_rated_current", 5000)) / 1000.0 or 5.0
        maximum = float(self.p.get("max_current", 1000)) / 1000.0 * rated
        return drive_max, rated, min(maximum, drive_max) if maximum > 0 else drive_max

    def phase_sign_of(self, value: int) -> int:
        """0x3410,2: 0x5555 (240°) drives the field forward, 0xAAAA (120°) backward."""
        return 1 if value == PHASE_240 else -1

    def phase_value(self, sign: int) -> int:
        return PHASE_240 if sign > 0 else 0xAAAA

    def _change_mode(self, mode: int) -> None:
        self.active_mode = mode
        self.write("mode_display", mode)
        handler = self.handlers.get(mode) if mode in self.profile.modes else None
        self._active_handler = handler
        if handler is not None:
            handler.configure()
            handler.enter()

    # -- contract -----------------------------------------------------------------------------------------------

    def step(self, dt: float) -> None:
        """One control period (longer `dt` runs several periods)."""
        if dt == self.dt:
            self._period()
            return
        for _ in range(max(1, round(dt / self.dt))):
            self._period()

    def on_sync(self) -> None:
        handler = self.handlers.get(self.active_mode)
        if isinstance(handler, InterpolatedPosition):
            handler.sync()

    def on_nmt_reset(self) -> None:
        """Warm reset: the node restored the objects; the drive restarts disabled and fault-free."""
        self.active_errors.clear()
        self.device_control = DeviceControl()
        self.device_control.initialised()
        if self.procedures.active is not None:
            self.procedures.end(ABORTED, raise_error=False)
        self.physics.power_cycle_sensor()
        if self.recorder is not None:
            self.recorder.reset()
        if self.sequencer is not None:
            self.sequencer.on_nmt_reset()
        self.loops.measure()
        if self.plant.feedback == FEEDBACK_ENCODER:
            self.phasing_valid = False
        self.position_offset_user = 0.0
        self.control_word = 0
        self.halted = False
        self.active_mode = 0
        self._active_handler = None
        if self.commissioned:
            self.apply_commissioning()
        self.write("supported_modes", self.profile.supported_modes_word)
        self.refresh_parameters()
        self._publish_all()

    # -- the period ---------------------------------------------------------------------------------------------

    def _period(self) -> None:
        """One control period: commands, set-points, loops and physics; supervision every millisecond."""
        self.time += self.dt
        periods = self._periods = self._periods + 1
        if self._dirty or periods % PARAMETER_REFRESH_PERIODS == 0:
            self.refresh_parameters()
        control_word = self._read_control_word()
        if control_word != self.control_word:
            self._on_control_word(control_word)
            self._supervise()
        elif periods % SUPERVISION_PERIODS == 0:
            self._supervise()
        device_control = self.device_control
        if device_control.phase is not _IDLE:  # enable and brake timers
            device_control.step(self.dt)
        if device_control.state is not self._published_state:
            self._publish_fast()
        loops = self.loops
        loops.measure()
        if self.procedures.active is not None:
            self.procedures.step()
        else:
            self._run_loops_for_state()
        physics = self.physics
        if physics.i_d * physics.i_d + physics.i_q * physics.i_q > self._overcurrent_squared:
            self.raise_error(errors.OVERCURRENT)
        physics.power_stage_on = loops.mode != MODE_OFF
        loops.step()
        if periods % SLOW_PUBLISH_PERIODS == 0:
            self._publish_slow()
        recorder = self.recorder
        if recorder is not None and recorder.armed:
            recorder.sample()  # after the period's update: the values a bus read would see now

    def _supervise(self) -> None:
        """Inputs, protections, current limit, brake and status word (every 1 ms and on each command)."""
        self._read_inputs()
        self._protect()
        self.loops.current_limit = self._current_limit()
        self.physics.brake_engaged = self.brake_engaged()
        self._publish_fast()

    def _on_control_word(self, control_word: int) -> None:
        previous = self.control_word
        self.control_word = control_word
        self.halted = self.profile.halt_bit and bool(control_word & CW_HALT)
        if control_word & CW_FAULT_RESET and not previous & CW_FAULT_RESET:
            self._fault_reset()
        was_following = self.device_control.follows_set_points
        self.device_control.command(decode_command(control_word), self._stop_options, self._can_enable())
        handler = self._active_handler
        if handler is not None:
            if self.device_control.follows_set_points and not was_following:
                handler.enter()
            handler.control_word(control_word, previous)

    def _can_enable(self) -> bool:
        return (
            self.phasing_valid and self.procedures.active is None and not self.inhibit_active
            and not self.quick_stop_input
        )  # fmt: skip

    def _run_loops_for_state(self) -> None:
        device_control = self.device_control
        loops = self.loops
        if not device_control.power_on:
            if loops.mode != MODE_OFF:
                loops.reset_integrators()
            loops.mode = MODE_OFF
            self._hold_position = loops.position
            return
        if loops.mode == MODE_OFF:
            loops.reset_integrators()
            self._hold_position = loops.position
            handler = self._active_handler
            if handler is not None:
                handler.enter()
        if device_control.phase is _STOPPING:
            self._run_stop()
        elif device_control.follows_set_points and self._active_handler is not None:
            self._active_handler.step()
            self._block_at_limits()
            if loops.mode == MODE_POSITION:
                self._hold_position = loops.position_ref
        else:
            loops.mode = MODE_POSITION
            loops.position_ref = self._hold_position
            loops.velocity_ff = loops.accel_ff = 0.0

    def _block_at_limits(self) -> None:
        """Hardware limit switch in the direction of travel: PP/HM/IP stop at maximum deceleration."""
        if not (self.negative_limit or self.positive_limit):
            return
        loops = self.loops
        handler = self._active_handler
        if handler is None or handler.uses_limit_switches or loops.mode != MODE_POSITION:
            return
        if self.limit_blocks(loops.velocity_ff):
            handler.limit_switch_stop()
            loops.position_ref = loops.position
            loops.velocity_ff = loops.accel_ff = 0.0

    def limit_blocks(self, demand: float) -> bool:
        return (demand > 0.0 and self.positive_limit) or (demand < 0.0 and self.negative_limit)

    def _run_stop(self) -> None:
        """Stop 1 (position loop, 0x3300,1 from the reference speed), Stop 2 (speed loop, 0x6085 from the actual
        speed) or Stop 3 (zero speed at the 0x3301,1 current limit), each with its time limit 0x3302."""
        device_control = self.device_control
        loops = self.loops
        stop = device_control.stop_type
        if self._stop_time == 0.0:
            self._stop_ramp_velocity = loops.velocity_ff if stop == STOP_SLOW_DOWN_RAMP else loops.speed
            if stop == STOP_SLOW_DOWN_RAMP and loops.mode != MODE_POSITION:
                self._stop_ramp_velocity = loops.speed
                loops.position_ref = loops.position
        self._stop_time += self.dt
        if stop == STOP_SLOW_DOWN_RAMP:
            decel = self.units.accel_to_rad(float(self.p.get("slow_down_ramp", 0))) or 1e3
            self._stop_ramp_velocity = _toward_zero(self._stop_ramp_velocity, decel * self.dt)
            loops.mode = MODE_POSITION
            loops.position_ref += self._stop_ramp_velocity * self.dt
            loops.velocity_ff = self._stop_ramp_velocity
            loops.accel_ff = 0.0
        else:
            if stop == STOP_QUICK_STOP_RAMP:
                decel = self.units.accel_to_rad(float(self.p.get("quick_stop_deceleration", 0))) or 1e3
                self._stop_ramp_velocity = _toward_zero(self._stop_ramp_velocity, decel * self.dt)
            else:
                self._stop_ramp_velocity = 0.0
            loops.mode = MODE_VELOCITY
            loops.velocity_ref = self._stop_ramp_velocity
            loops.velocity_ff = loops.accel_ff = 0.0
        limit_name = "stop_time_current" if stop == STOP_CURRENT_LIMIT else "stop_time_ramp"
        time_limit = float(self.p.get(limit_name, 1000)) / 1000.0
        finished = self._stop_ramp_velocity == 0.0 and abs(loops.speed) < STANDSTILL_SPEED
        if finished or (time_limit > 0 and self._stop_time > time_limit):
            self._stop_time = 0.0
            self._hold_position = loops.position
            device_control.stop_finished(self._stop_options)
            if not finished and device_control.state is not State.FAULT:
                self.raise_error(errors.STOP_FAILED)

    def _base_current_limit(self) -> float:
        """0x6073 (capped by the drive) scaled by the dynamic limit 0x30D1 (0x3FFF = 100 %, 0x30D2 bit 0 reverses)."""
        dynamic = float(self.p.get("dynamic_current_limit", 0x3FFF))
        if int(self.p.get("dynamic_current_limit_config", 0)) & 1:
            dynamic = 0x3FFF - dynamic
        return self.max_current * max(0.0, min(dynamic, 0x3FFF)) / 0x3FFF

    def _current_limit(self) -> float:
        limit = self._limit
        if self.i2t.limiting:
            limit = min(limit, self.rated_current)
        if self.device_control.stop_type == STOP_CURRENT_LIMIT:
            limit = min(limit, self.stop_current())
        handler = self._active_handler
        if handler is not None:
            limit = min(limit, handler.current_limit())
        return limit

    def stop_current(self) -> float:
        """Stop 3 current limit: 0x3301,1 in ‰ of the rated current 0x6075."""
        return float(self.p.get("stop_current_limit", 1000)) / 1000.0 * self.rated_current

    def homing_current(self) -> float:
        """Mechanical-stop homing limit: 0x309C with 0x3FFF = the drive max current 0x6510,1."""
        return float(self.p.get("homing_current_limit", 0x400)) / 0x3FFF * self.drive_max_current

    def brake_engaged(self) -> bool:
        if not self.plant.has_brake:
            return False
        if int(self.p.get("digital_output_mask", 0)) & 1:
            return bool(int(self.p.get("digital_outputs", 0)) & 1)
        return not self.device_control.brake_released

    # -- inputs and protections ---------------------------------------------------------------------------------

    def _read_inputs(self) -> None:
        """The input functions of 0x60FD (bits 0–15) and what the drive does on them: a limit switch blocks its
        direction, INHIBIT disables, RESET and QUICK STOP act on their edges, homing looks for the limit and home
        switches here; ENABLE and motor phasing only show (docs/io.md)."""
        word, owned = self.input_word()
        self.negative_limit, self.positive_limit, self.home_switch = bool(word & 1), bool(word & 2), bool(word & 4)
        self._act_on_edges(word)
        inhibit = bool(word & INPUT_INHIBIT)
        if inhibit != self._routed_inhibit:
            self._routed_inhibit = inhibit
            self.set_inhibit(inhibit)
        if word != self._published_inputs:
            self._published_inputs = word
            if self.has("digital_inputs"):
                current = int(self.p.get("digital_inputs", 0)) & ~owned
                self.write("digital_inputs", current | word)

    def _act_on_edges(self, word: int) -> None:
        """RESET resets the faults whose cause has gone on its rising edge, as control word bit 7 does; QUICK STOP
        quick-stops an enabled axis on its rising edge and keeps it from being enabled while active (manual §3.2.5.1:
        the 0x60FD function bits 12 and 15)."""
        rising, self._input_levels = word & ~self._input_levels, word
        self.quick_stop_input = bool(word & INPUT_QUICK_STOP)
        if rising & INPUT_RESET:
            self._fault_reset()
        if rising & INPUT_QUICK_STOP:
            self.device_control.command(Command.QUICK_STOP, self._stop_options)

    def input_word(self) -> tuple[int, int]:
        """(the bits of 0x60FD this model sets, their mask): the plant's own limit and home switches, which act on
        the drive's functions directly, and the functions the logic-input routing gives (``routed_inputs``)."""
        physics = self.physics
        plant = (
            (physics.negative_limit_active() and 1)
            | (physics.positive_limit_active() and 2)
            | (physics.home_switch_active() and 4)
        )
        return plant | self.routed_inputs, INPUT_FUNCTIONS

    def _protect(self) -> None:
        physics = self.physics
        loops = self.loops
        current = math.hypot(physics.i_d, physics.i_q)
        bus = physics.dc_bus
        if bus > self.plant.overvoltage:
            self.raise_error(errors.OVERVOLTAGE)
        if bus < self._undervoltage and self.device_control.power_on:
            self.raise_error(errors.UNDERVOLTAGE)
        electrical_hz = self.plant.pole_pairs * physics.omega_motor / TWO_PI
        if self.i2t.step(current, self.rated_current, electrical_hz) and self._fusing:
            self.raise_error(errors.I2T)
        if self.device_control.follows_set_points and loops.mode != MODE_OFF:
            self._check_following(loops)
            self._check_software_limits()
        else:
            self.following_error_active = False
            self._following_time = 0.0
        self._check_motor_temperature()

    def _check_software_limits(self) -> None:
        """0x607D acts only on a linear axis (0x3360 = 1): leaving the range is error 36."""
        if int(self.p.get("axis_type", 0)) != 1:
            return
        position = self.actual_position_user()
        low = self.p.get("software_limit_min")
        high = self.p.get("software_limit_max")
        if (low is not None and position < low) or (high is not None and position > high):
            self.raise_error(errors.SOFTWARE_LIMIT)

    def _check_motor_temperature(self) -> None:
        """Digital probe (0x3324,1 = 2): warning above 0x3324,4, error 37 above 0x3324,5 (°C)."""
        if int(self.p.get("probe_type", 0)) != 2:
            self.temperature_warning = False
            return
        temperature = self.physics.temperature
        self.temperature_warning = temperature > float(self.p.get("probe_warning_celsius", 100))
        if temperature > float(self.p.get("probe_error_celsius", 100)):
            self.raise_error(errors.MOTOR_TEMPERATURE)

    def set_inhibit(self, active: bool) -> None:
        """The INHIBIT input (simulated wiring): while active the drive cannot be enabled; activating it in
        operation stops with the 0x305A option code and disables (manual §2.4.21)."""
        self.inhibit_active = active
        if active:
            self.device_control.inhibit(int(self.p.get("inhibit_code", 1)))

    def _check_following(self, loops: ServoLoops) -> None:
        units = self.units
        window = int(self.p.get("following_error_window", U32_OFF))
        if loops.mode == MODE_POSITION and window not in (0, U32_OFF) and loops.kpp > 0:
            error = loops.position_ref - loops.position
            if int(self.p.get("following_error_mode", 0)) == 1:
                error -= loops.velocity_ff * (1.0 - loops.kfp) / loops.kpp
            if abs(units.to_user(error)) >= window:
                self._following_time += self.dt * SUPERVISION_PERIODS
                if self._following_time * 1000.0 >= float(self.p.get("following_error_timeout", 0)):
                    self.following_error_active = True
                    self.raise_error(errors.POSITION_FOLLOWING)
            else:
                self._following_time = 0.0
        threshold = int(self.p.get("speed_error_threshold", U32_OFF))
        if (
            threshold != U32_OFF
            and loops.mode in (MODE_POSITION, MODE_VELOCITY)
            and abs(units.speed_to_user(loops.speed_demand - loops.speed)) >= threshold
        ):
            self.raise_error(errors.SPEED_FOLLOWING)

    # -- errors -------------------------------------------------------------------------------------------------

    def raise_error(self, error: DriveError | int) -> None:
        """Latch a drive error: error bits, 0x603F, EMCY, fault reaction (also the fault-injection entry)."""
        if isinstance(error, int):
            error = errors.CATALOGUE.get(error) or DriveError(error, f"error {error}", 0x1000)
        if error.code in self.active_errors:
            return
        if self.error_inhibited(error):
            return
        self.active_errors[error.code] = error
        self._publish_errors(error)
        self.send_emergency(error)
        self.device_control.fault(self.fault_reaction(error))
        if self.procedures.active is not None:
            self.procedures.end(FAILED, raise_error=False)

    def error_inhibited(self, error: DriveError) -> bool:
        """0x3025,1/2: inhibit masks."""
        return bool(int(self.p.get(f"error_inhibit_{error.word}", 0)) & error.mask)

    def fault_reaction(self, error: DriveError) -> int:
        """Stop 2 / Stop 3 by the 0x3025,3..6 masks (allowed codes only), else Stop 0."""
        return errors.stop_for(
            error.code, int(self.p.get(f"error_stop2_{error.word}", 0)), int(self.p.get(f"error_stop3_{error.word}", 0))
        )

    def send_emergency(self, error: DriveError) -> None:
        """EMCY: CiA 402 code, Infranor code in byte 3 (decisions.md §5)."""
        self.events.emergency(error.cia_code, error.code)

    def _publish_errors(self, latest: DriveError | None) -> None:
        word_1 = word_2 = 0
        for error in self.active_errors.values():
            if error.word == 1:
                word_1 |= error.mask
            else:
                word_2 |= error.mask
        self.write("error_word_1", word_1)
        self.write("error_word_2", word_2)
        self.write("error_code", latest.cia_code if latest else 0)
        self.write("infranor_error_code", latest.code if latest else 0)

    def _fault_reset(self) -> None:
        """Rising edge of control word bit 7: clear the errors whose cause has gone (transition 15)."""
        if not self.active_errors:
            return
        for code in list(self.active_errors):
            if not self._cause_present(code):
                del self.active_errors[code]
        remaining = next(iter(self.active_errors.values()), None)
        self._publish_errors(remaining)
        if remaining is None:
            self.following_error_active = False
            self.i2t.limiting_time = 0.0
            self.device_control.fault_reset()
            self.events.emergency_cleared()
            handler = self.handlers.get(MODE_HM)
            if isinstance(handler, HomingMode):
                handler.error = False

    def _cause_present(self, code: int) -> bool:
        physics = self.physics
        if code == errors.OVERVOLTAGE.code:
            return physics.dc_bus > self.plant.overvoltage
        if code == errors.UNDERVOLTAGE.code:
            return physics.dc_bus < float(self.p.get("undervoltage_threshold", 0))
        if code == errors.I2T.code:
            return self.i2t.limiting
        return False

    def hold_here(self) -> None:
        """Hold the actual position when the loops next run (after a procedure or a stop)."""
        self._hold_position = self.loops.position

    def parameters_changed(self) -> None:
        """Re-read the parameters before the next period (after the drive itself changed them)."""
        self._dirty = True

    # -- homing support -----------------------------------------------------------------------------------------

    def set_home(self, home_rad: float, offset: float) -> None:
        """Make the position at `home_rad` read as the home offset (0x607C, or a HOME sequence's) from now on."""
        self.position_offset_user = offset - self.units.to_user(home_rad)

    def index_position_rad(self) -> float:
        """The last index pulse in the drive's position coordinates."""
        return self.physics.counter_turns(self.physics.index_turns) * TWO_PI

    # -- positions in bus units ---------------------------------------------------------------------------------

    def actual_position_user(self) -> float:
        return self.units.to_user(self.loops.position) + self.position_offset_user

    def rad_to_user_position(self, rad: float) -> float:
        return self.units.to_user(rad) + self.position_offset_user

    def user_to_rad_position(self, user: float) -> float:
        return self.units.to_rad(user - self.position_offset_user)

    # -- publishing ---------------------------------------------------------------------------------------------

    def _publish_fast(self) -> None:
        """Every 1 ms and on state changes: monitor filters (0x3078, 0x306C) and the status word (event TPDOs)."""
        loops = self.loops
        self._current_filter += self._current_filter_alpha * (loops.i_q - self._current_filter)
        self._velocity_filter += self._velocity_filter_alpha * (loops.speed - self._velocity_filter)
        self._published_state = self.device_control.state
        status = self.status_word()
        if status != self._published_status:
            self._published_status = status
            self.write("status_word", status)

    def _measurement_functions(self) -> dict[str, Callable[[], int]]:
        """The fast measurements in bus units (computed on every bus/PDO/recorder read, stored every 8 ms), one
        function each: a read computes only its own object, which keeps an armed recorder cheap."""
        return {
            "position_actual": lambda: _wrap_i32(self.units.to_user(self.loops.position) + self.position_offset_user),
            "velocity_actual": lambda: _wrap_i32(self.units.speed_to_user(self._velocity_filter)),
            "position_demand": lambda: _wrap_i32(self.units.to_user(self._demand_rad()) + self.position_offset_user),
            "following_error_actual": lambda: _wrap_i32(self.units.to_user(self._demand_rad() - self.loops.position)),
            "current_actual": lambda: _clamp_i16(1000.0 * self._current_filter / self.rated_current),
        }

    def _demand_rad(self) -> float:
        loops = self.loops
        return loops.position_ref if loops.mode == MODE_POSITION else loops.position

    def _measurements(self) -> dict[str, int]:
        return {name: measure() for name, measure in self._measure.items()}

    def _measurement_reader(self, name: str):
        measure = self._measure[name]
        return lambda index, sub: measure()

    def _publish_slow(self) -> None:
        for name, value in self._measurements().items():
            self.write(name, value)
        loops = self.loops
        physics = self.physics
        units = self.units
        self.write(
            "velocity_demand",
            units.speed_to_user(loops.speed_demand if loops.mode != MODE_POSITION else loops.velocity_ff),
            integer=True,
        )
        self.write("velocity_rpm", loops.speed / RPM, integer=True)
        self.write("torque_demand", _clamp_i16(1000.0 * loops.current_demand / self.rated_current))
        self.write("torque_actual", _clamp_i16(1000.0 * loops.i_q / self.rated_current))
        self.write("current_monitor", _clamp_i16(0x3FFF * loops.i_q / self.drive_max_current))
        self.write("dc_voltage_mv", physics.dc_bus * 1000.0, integer=True)
        self.write("dc_voltage_v", round(physics.dc_bus))
        self.write("position_internal", physics.sensor_counts(), integer=True)
        self.write("motor_temperature", round(physics.temperature))
        self.write("i2t_signal", self.i2t.signal(self.drive_max_current))
        self.write("i2t_current", min(0x7FFF, round(0x7FFF * math.sqrt(self.i2t.mean_square) / self.drive_max_current)))
        self._linked_bits = self._linked_status_bits()
        warnings = self._warnings()
        if warnings != self.warnings:
            self.warnings = warnings
            self.write("warning_word", warnings)
        if self.has("digital_outputs"):
            self._publish_outputs()

    def _publish_outputs(self) -> None:
        """0x60FE,1: the outputs the sources 0x3054 drive (``outputs.py``), the bus's others, and bit 0 the brake
        unless the bit mask 0x60FE,2 gives it to the bus."""
        current = int(self.p.get("digital_outputs", 0))
        bits, mask = self.outputs.routed()
        outputs = current & ~mask | bits
        if not int(self.p.get("digital_output_mask", 0)) & 1:
            outputs = outputs & ~1 | (0 if self.device_control.brake_released else 1)
        self.write("digital_outputs", outputs)
        if mask:
            self.outputs.show(outputs)

    def _warnings(self) -> int:
        warnings = 0
        if self.negative_limit or self.positive_limit:
            warnings |= errors.WARNING_LIMIT_SWITCH
        if self.i2t.warning:
            warnings |= errors.WARNING_I2T
        if not self.phasing_valid:
            warnings |= errors.WARNING_PHASING_NOT_OK
        if self.temperature_warning:
            warnings |= errors.WARNING_MOTOR_TEMPERATURE
        return warnings

    def _publish_all(self) -> None:
        self._publish_errors(None)
        self._publish_fast()
        self._publish_slow()

    def status_word(self) -> int:
        device_control = self.device_control
        status = STATE_BITS[device_control.state] | REMOTE
        if self.warnings:
            status |= WARNING
        if self.procedures.active is not None or getattr(self.events, "flash_busy", False):
            status |= BUSY
        handler = self._active_handler
        if device_control.state is State.QUICK_STOP_ACTIVE:
            # CiA 402: in Quick Stop Active bit 10 means "the quick stop has ended, the axis stands still"; the
            # mode's own target is not being followed
            if handler is not None:
                status |= handler.status_bits() & ~BIT_TARGET_REACHED
            if device_control.phase is not _STOPPING:
                status |= BIT_TARGET_REACHED
        elif device_control.state is State.OPERATION_ENABLED and handler is not None:
            status |= handler.status_bits()
        elif handler is not None:
            status |= handler.not_following()
        return status | self._linked_bits

    def _linked_status_bits(self) -> int:
        """Status word bits 8 and 14 copied from any object bit (0x3044 links: index<<16 | sub<<8 | bit)."""
        bits = 0
        for name, bit in (("status_bit8_link", 8), ("status_bit14_link", 14)):
            link = int(self.p.get(name, 0))
            if link:
                address = ((link >> 16) & 0xFFFF, (link >> 8) & 0xFF)
                if address in self.store and int(self.store.get(*address)) >> (link & 0x1F) & 1:
                    bits |= 1 << bit
        return bits


def _wrap_i32(value: float) -> int:
    number = round(value) & 0xFFFFFFFF
    return number - (1 << 32) if number & 0x80000000 else number


def _clamp_i16(value: float) -> int:
    return max(-32768, min(32767, round(value)))


def _toward_zero(value: float, step: float) -> float:
    if abs(value) <= step:
        return 0.0
    return value - math.copysign(step, value)
