"""TR-Electronic encoTRive MD-025 on the shared engine (manual 004, docs/devices.md).

A motor-integrated positioning drive: factory-calibrated commutation and current loop (no phasing or tuning
objects), a speed controller whose gains the drive derives from the inertia setting 2F02h,8 (Θi, p. 218), profile
position and profile velocity only, no homing (absolute measuring system), position units through 0x6093
numerator/divisor on 0x608F,1 increments per revolution, speeds in rpm and accelerations in rpm/s (the factory
setting of the velocity factor), following error with window 0x6065 and time-out 0x6066, writable actual position
0x6064 (preset), DS-301 EMCY codes without an Infranor byte, error history 0x1003.
"""

from __future__ import annotations

from typing import Any

from servostudio.sim.drive import gains
from servostudio.sim.drive.behaviour import DriveBehaviour
from servostudio.sim.drive.device_map import _COMMON_402, DeviceProfile
from servostudio.sim.drive.errors import DriveError
from servostudio.sim.drive.statemachine import STOP_NONE, STOP_QUICK_STOP_RAMP
from servostudio.sim.drive.units import RPM, UnitScaling

ENCOTRIVE = DeviceProfile(
    key="encotrive",
    objects={
        name: address
        for name, address in _COMMON_402.items()
        if address[0] not in (0x60F6, 0x60F9, 0x60FB, 0x6410, 0x6510, 0x6098, 0x6099, 0x609A, 0x607C)
    }
    | {
        "fault_reaction_code": (0x605E, 0),
        "max_torque": (0x6072, 0),
        "rated_torque": (0x6076, 0),
        "speed_controller_inertia": (0x2F02, 8),
    },
    modes=frozenset({1, 3}),
    supported_modes_word=0x05,
    default_mode=1,
)


#: Factory values where the encotrive.eds has no DefaultValue because the manual's excerpt cuts them off
#: (docs/devices.md §12): 6083h prints as "400…", read as 4000 rpm/s; 6084h as the manual's commissioning example
#: writes it (12000, p. 249); 60C5h as the printed 60C6h (15000); 607Fh as the printed 6081h (4400 rpm), so the
#: default profile velocity is reachable.  The manual's visible ones (6081h 4400, 6085h 9000, 60C6h 15000) are the
#: dictionary's.  A drive with a 0 in any of them would not move in positioning or speed ramp mode.
FACTORY_VALUES: dict[tuple[int, int], int] = {
    (0x607F, 0): 4400,
    (0x6083, 0): 4000,
    (0x6084, 0): 12000,
    (0x60C5, 0): 15000,
}


class EncoTriveBehaviour(DriveBehaviour):
    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        address = self.profile.address("position_actual")
        if address is not None and address in self.store:
            self.store.on_write(address[0], address[1], self._preset_position)

    def set_hardware_data(self) -> None:
        """The manual's ramps and speed limits where the dictionary leaves them open, the integrated motor's rating
        (6075h mA, 6076h mN·m) and rotor inertia (2F02h,8 Θi, the load unknown: the factory knows its motor only),
        then the common values."""
        plant = self.plant
        torque = plant.torque_constant * plant.stall_current
        rating = {
            (0x6075, 0): round(plant.stall_current * 1000),
            (0x6076, 0): round(torque * 1000),
            (0x2F02, 8): max(1, round(plant.motor_inertia / gains.INERTIA_SETTING_UNIT)),
        }
        for (index, sub), value in (FACTORY_VALUES | rating).items():
            if (index, sub) in self.store and self.store.od[index, sub].default_for(self.store.node_id) is None:
                self.store.set_factory(index, sub, value)
        super().set_hardware_data()

    def _preset_position(self, index: int, sub: int, value: Any) -> None:
        """Writing 0x6064 sets the current position to `value` (absolute system preset)."""
        self.position_offset_user = float(value) - self.units.to_user(self.loops.position)

    def read_units(self) -> UnitScaling:
        increments = float(self.p.get("encoder_increments", 4096)) or 4096.0
        numerator = float(self.p.get("position_factor_numerator", 1)) or 1.0
        divisor = float(self.p.get("position_factor_denominator", 1)) or 1.0
        return UnitScaling(increments * divisor / numerator, speed_unit_rad=RPM, accel_unit_rad=RPM)

    def read_currents(self) -> tuple[float, float, float]:
        plant = self.plant
        rated = float(self.p.get("rated_current", 0)) / 1000.0 or plant.stall_current
        maximum = float(self.p.get("max_current", 0)) / 1000.0 * rated or plant.peak_current
        return plant.peak_current, rated, min(maximum, plant.peak_current)

    def apply_commissioning(self) -> None:
        """The factory calibration matches the motor; what a machine's commissioning sets is the inertia setting Θi
        (2F02h,8) to rotor plus load (the factory value is the rotor alone, restored by a restore-defaults)."""
        self.phasing_valid = True
        address = self.profile.address("speed_controller_inertia")
        assert address is not None  # the encoTRive's map names it
        self.store.set(*address, max(1, round(self.plant.total_inertia / gains.INERTIA_SETTING_UNIT)))

    def refresh_parameters(self) -> None:
        """Commutation and current loop run with the factory calibration of the integrated motor, the speed loop
        with the gains the drive derives from its inertia setting."""
        super().refresh_parameters()
        plant = self.plant
        loops = self.loops
        loops.pole_pairs = plant.pole_pairs
        loops.phase_sign = plant.phase_sign
        loops.offset_turns = plant.sensor_offset / 65536.0
        loops.emf_constant = plant.torque_constant / 1.5
        current = gains.current_loop_gains(plant.inductance, 0)
        loops.kp_q = loops.kp_d = current.kp_q * gains.CURRENT_KP_UNIT
        loops.ki_q = loops.ki_d = current.ki_q * gains.CURRENT_KI_UNIT
        self._speed_controller_from_inertia()

    def _speed_controller_from_inertia(self) -> None:
        """The speed and position loop follow the inertia setting Θi (2F02h,8) and the rating 6075h / 6076h as the
        drive computes them (p. 218, gains.inertia_speed_gains): writing a larger Θi raises the bandwidth."""
        plant, read, loops = self.plant, self.p.get, self.loops
        inertia = float(read("speed_controller_inertia", 0)) * gains.INERTIA_SETTING_UNIT or plant.motor_inertia
        rated_torque = float(read("rated_torque", 0)) / 1000.0 or plant.torque_constant * plant.stall_current
        rated_current = float(read("rated_current", 0)) / 1000.0 or plant.stall_current
        derived = gains.inertia_speed_gains(inertia, rated_torque, rated_current)
        loops.kpv, loops.kiv, loops.kav, loops.kpp = derived.kpv, derived.kiv, derived.kav, derived.kpp
        loops.kbv = 0.0
        loops.kfp = 1.0

    def fault_reaction(self, error: DriveError) -> int:
        """0x605E: 0 switch off, 1/2 decelerate (quick-stop ramp here), 3 current limit."""
        code = int(self.p.get("fault_reaction_code", 0))
        return STOP_QUICK_STOP_RAMP if code in (1, 2, 3) else STOP_NONE

    def error_inhibited(self, error: DriveError) -> bool:
        return False

    def send_emergency(self, error: DriveError) -> None:
        self.events.emergency(error.cia_code)

    def _publish_errors(self, latest: DriveError | None) -> None:
        self.write("error_code", latest.cia_code if latest else 0)
