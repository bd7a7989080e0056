"""Runs the drive's signature procedures (decisions.md §4) on behalf of a `DriveBehaviour`.

The trigger objects get a write hook (signature starts, 0 aborts, anything else is ignored) and a read hook
(the status 0–5). While a procedure runs it owns the loops: auto-phasing and motor phasing drive a forced current
vector, auto-tuning drives the q current. 'calc' and the current-limit calculation finish at once.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from servostudio.sim.drive import errors, gains
from servostudio.sim.drive.device_map import MODE_PV
from servostudio.sim.drive.loops import MODE_FORCED_VECTOR, MODE_OFF, MODE_TORQUE
from servostudio.sim.drive.physics import TWO_PI
from servostudio.sim.drive.procedures import (
    ABORTED,
    CANNOT_EXECUTE,
    DONE,
    FAILED,
    RUNNING,
    AutoPhasing,
    MotorPhasing,
    ProcedureSlot,
    signature,
)
from servostudio.sim.drive.statemachine import State
from servostudio.sim.drive.tuning import AutoTuning, Identified

if TYPE_CHECKING:
    from servostudio.sim.drive.behaviour import DriveBehaviour

_DISABLED_STATES = (State.SWITCH_ON_DISABLED, State.READY_TO_SWITCH_ON, State.SWITCHED_ON)


class ProcedureRunner:
    def __init__(self, drive: DriveBehaviour) -> None:
        self.drive = drive
        self.slots: dict[str, ProcedureSlot] = {name: ProcedureSlot(name) for name in drive.profile.procedures}
        self.active: Any = None
        self.active_name = ""
        store = drive.store
        for name, address in drive.profile.procedures.items():
            if address in store:
                store.on_write(address[0], address[1], self._write_hook(name))
                store.on_read(address[0], address[1], self._read_hook(name))

    def _write_hook(self, name: str):
        start = signature(name if name != "clim" else "calc")

        def hook(index: int, sub: int, value: Any) -> None:
            if value == 0 and self.slots[name].running:
                self.end(ABORTED, raise_error=False)
            elif value == start:
                self.start(name)

        return hook

    def _read_hook(self, name: str):
        return lambda index, sub: self.slots[name].status

    def start(self, name: str) -> None:
        drive = self.drive
        drive.refresh_parameters()
        slot = self.slots[name]
        if self.active is not None:
            slot.status = CANNOT_EXECUTE
            return
        if name == "calc":
            self._calculate_current_loop()
            slot.status = DONE
            return
        if name == "clim":
            drive.apply_current_limits(
                float(drive.live("motor_stall_current", 0)), float(drive.live("motor_peak_current", 0))
            )
            slot.status = DONE
            return
        procedure = self._create(name)
        if procedure is None:
            slot.status = CANNOT_EXECUTE
            return
        if drive.negative_limit or drive.positive_limit:
            slot.status = FAILED
            drive.raise_error(errors.PROCEDURE)
            return
        self.active = procedure
        self.active_name = name
        slot.status = RUNNING
        drive.loops.reset_integrators()

    def _create(self, name: str) -> Any:
        """A procedure needs the drive disabled without fault; auto-tuning may also run enabled at standstill (a
        vertical load, manual §1.8.16: "if the axis is moving, the procedure has not been accepted")."""
        drive = self.drive
        state = drive.device_control.state
        disabled = state in _DISABLED_STATES and not drive.device_control.power_on
        current = min(drive.rated_current, drive.max_current)
        if name == "apha" and disabled:
            return AutoPhasing(drive.dt, current)
        if name == "mcal" and disabled:
            return MotorPhasing(drive.dt, current, drive.loops.pole_pairs, drive.loops.phase_sign)
        enabled = state is State.OPERATION_ENABLED
        at_standstill = enabled and abs(drive.loops.speed) < 1.0
        if name == "atun" and (disabled or at_standstill) and not drive.brake_engaged():
            # enabled (a vertical load): the current that holds the axis now keeps holding it while tuning
            return AutoTuning(drive.dt, current, self._torque_constant(), drive.loops.i_q if enabled else 0.0)
        return None

    def _torque_constant(self) -> float:
        """N·m/A from the motor data; a drive without a torque constant object (CD1-k) identifies per N·m/A."""
        drive = self.drive
        if not drive.has("motor_torque_constant"):
            return 1.0
        return float(drive.p.get("motor_torque_constant", 0)) * 1e-3

    def step(self) -> None:
        """One period of the running procedure, which owns the loops."""
        procedure = self.active
        loops = self.drive.loops
        if isinstance(procedure, AutoTuning):
            finished = procedure.step(loops.position, loops.speed, loops.i_q)
            loops.mode = MODE_TORQUE
            loops.current_ref = procedure.current_demand
        else:
            if self.active_name == "apha":
                loops.phase_sign = 1  # identify against phase order 0x5555
            finished = procedure.step(loops.position / TWO_PI)
            loops.mode = MODE_FORCED_VECTOR
            loops.forced_angle = procedure.angle
            loops.forced_current = procedure.current
        if finished:
            self._finish()

    def _finish(self) -> None:
        procedure = self.active
        result = procedure.result
        if result is None:
            self.end(FAILED, raise_error=True)
            return
        drive = self.drive
        if isinstance(procedure, AutoTuning):
            self._apply_tuning(result)
        else:
            drive.write("control_pole_pairs", result.pole_pairs)
            drive.write("control_phase", drive.phase_value(result.phase_sign))
            drive.write("control_offset", result.offset)
            drive.phasing_valid = True
        self.end(DONE, raise_error=False)

    def end(self, status: int, raise_error: bool) -> None:
        """Stop the running procedure with `status`; the loops switch off."""
        drive = self.drive
        name = self.active_name
        self.active = None
        self.active_name = ""
        drive.loops.mode = MODE_OFF
        drive.loops.reset_integrators()
        drive.hold_here()
        if name:
            self.slots[name].status = status
        drive.parameters_changed()
        if raise_error:
            drive.raise_error(errors.PROCEDURE)

    def _calculate_current_loop(self) -> None:
        """'calc': gains from the inductance 0x340F (0.1 mH), and the current limits (0x3412 rule)."""
        drive = self.drive
        inductance = float(drive.live("control_inductance", 0)) * 1e-4
        result = gains.current_loop_gains(inductance, int(drive.live("current_regulator_type", 0)))
        drive.write("kp_current_q", result.kp_q)
        drive.write("ki_current_q", result.ki_q)
        drive.write("kp_current_d", result.kp_d)
        drive.write("ki_current_d", result.ki_d)
        drive.apply_current_limits(
            float(drive.live("motor_stall_current", 0)), float(drive.live("motor_peak_current", 0))
        )
        drive.parameters_changed()

    def _apply_tuning(self, identified: Identified) -> None:
        drive = self.drive
        p = drive.p
        code, filter_type = self._tuning_codes()
        bandwidth = gains.TUNING_BANDWIDTH_HZ.get(code, 75.0)
        selection = int(p.get("tuning_speed_filter", 0))
        result = gains.tuned_gains(
            identified.inertia,
            identified.torque_constant,
            bandwidth,
            position_loop=drive.active_mode != MODE_PV,
            minimum_following_error=int(p.get("tuning_requirement", 0)) == 0,
            viscous_friction=identified.viscous_friction,
            speed_filter=None if selection == 0 else selection - 1,
            anti_resonance=filter_type == 1,
            resonance_hz=identified.resonance_hz,
        )
        for name, value in (
            ("kp_speed", result.kpv),
            ("ki_speed", result.kiv),
            ("ki_speed_filter", result.kivf),
            ("kc_speed", result.kcv),
            ("kd_speed", result.kdv),
            ("kd_speed_filter", result.kdvf),
            ("kj_speed", result.kjv),
            ("kp_position", result.kpp),
            ("kf_position", result.kfp),
            ("ka_position", result.kav),
            ("kb_position", result.kbv),
            ("speed_filter", result.speed_filter),
        ):
            drive.write(name, value)
        filters = ("current_filter_1", "current_filter_2", "current_filter_3")
        for name, corner in zip(filters, result.current_filters, strict=True):
            drive.write(name, corner)
        self._publish_identified(identified)

    def _tuning_codes(self) -> tuple[int, int]:
        """(bandwidth 0..2, filter type 0..2): 0x3425,1 and ,2; the CD1-k codes both in 0x3420,1 (0..8)."""
        p = self.drive.p
        code = int(p.get("tuning_bandwidth", 1))
        if self.drive.has("tuning_filter_type"):
            return code, int(p.get("tuning_filter_type", 0))
        return code % 3, code // 3

    def _publish_identified(self, identified: Identified) -> None:
        """0x3428 "Identified plant" (contract of issue #13); 0x3428,4 is the load's torque in the + direction."""
        drive = self.drive
        for name, value in (
            ("identified_inertia", identified.inertia),
            ("identified_viscous_friction", identified.viscous_friction),
            ("identified_coulomb_friction", identified.coulomb_friction),
            ("identified_load_torque", -identified.load_torque),
            ("identified_residual", identified.residual),
        ):
            drive.write(name, value)
