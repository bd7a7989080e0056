"""Infranor CD1-k on the shared engine (manual 001, docs/devices.md).

Differences from the XtrapulsPac that the simulation reproduces:
- positions in increments with 0x608F,1 increments per revolution (no factor group), speeds inc/s;
- currents in % of the drive rating 0x6510,4 (0.01 A) with 0x3FFF = 100 %: 0x6510,5 max, 0x6510,6 rated;
- commutation data in 0x6410,2..4 (phase order 0/1), auto-phasing 'apha' on 0x3410, motor phasing 'mcal' on 0x3414,
  auto-tuning 'atun' on 0x3420,2 with bandwidth 0x3420,1;
- the gain records have other sub-indices (0x60F6,1..4 q/d, 0x60F9,1 KP … 0x60FB,1 KPp …);
- errors in the 0x3020 bit field (EMCY bytes 3–6), fault reactions by the masks 0x3330 (Stop 1) / 0x3331 (Stop 3);
- stop current 0x3301 and homing current 0x309C with 0x3FFF = 100 % (of the rating / of the max current);
- no halt bit; default mode ip (7).
The scalings of the gains are the project's (docs/control-loops.md), as for the XtrapulsPac.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from servostudio.od.model import Value
from servostudio.sim.drive import errors
from servostudio.sim.drive.behaviour import DriveBehaviour, _clamp_i16
from servostudio.sim.drive.device_map import _COMMON_402, IDENTIFIED_PLANT, DeviceProfile
from servostudio.sim.drive.errors import DriveError
from servostudio.sim.drive.statemachine import STOP_CURRENT_LIMIT, STOP_NONE, STOP_SLOW_DOWN_RAMP
from servostudio.sim.drive.units import UnitScaling

FULL_SCALE = 0x3FFF

CD1K = DeviceProfile(
    key="cd1k",
    objects={
        name: address
        for name, address in _COMMON_402.items()
        if address[0] not in (0x60F6, 0x60F9, 0x60FB, 0x6410, 0x6510, 0x6093, 0x6073, 0x6075)
    }
    | {
        "kp_current_q": (0x60F6, 1),
        "ki_current_q": (0x60F6, 2),
        "kp_current_d": (0x60F6, 3),
        "ki_current_d": (0x60F6, 4),
        "kp_speed": (0x60F9, 1),
        "ki_speed": (0x60F9, 2),
        "kc_speed": (0x60F9, 4),
        "kd_speed": (0x60F9, 7),
        "kp_position": (0x60FB, 1),
        "kf_position": (0x60FB, 2),
        "ka_position": (0x60FB, 3),
        "kb_position": (0x60FB, 4),
        "control_pole_pairs": (0x6410, 2),
        "control_phase": (0x6410, 3),
        "control_offset": (0x6410, 4),
        "drive_rating": (0x6510, 4),
        "max_current_share": (0x6510, 5),
        "rated_current_share": (0x6510, 6),
        "i2t_mode": (0x6510, 7),
        "error_bits": (0x3020, 0),
        "warning_word": (0x3021, 0),
        "fault_reaction_stop1": (0x3330, 0),
        "fault_reaction_stop3": (0x3331, 0),
        "inhibit_code": (0x305A, 0),
        "homing_current_limit": (0x309C, 0),
        "dynamic_current_limit": (0x30D1, 0),
        "current_monitor": (0x30D4, 0),
        "slow_down_ramp": (0x3300, 1),
        "stop_current_limit": (0x3301, 0),
        "drive_reaction_time": (0x3304, 0),
        "brake_reaction_time": (0x3305, 0),
        "tuning_bandwidth": (0x3420, 1),
        "tuning_requirement": (0x3430, 0),
        "input_mask": (0x30FD, 0),
        "sim_physical_inputs": (0x5F00, 0),
        **IDENTIFIED_PLANT,
    },
    modes=frozenset({1, 3, 4, 6, 7}),
    procedures={"apha": (0x3410, 0), "mcal": (0x3414, 0), "atun": (0x3420, 2)},
    supported_modes_word=0x6D,
    default_mode=7,
    halt_bit=False,
)

# Infranor (XtrapulsPac) code → 0x3020 bit value of the CD1-k
_ERROR_BITS = {
    errors.SOFTWARE_LIMIT.code: 1 << 0,
    errors.I2T.code: 1 << 1,
    errors.ENCODER_COUNTING.code: 1 << 2,
    errors.POSITION_FOLLOWING.code: 1 << 3,
    errors.SPEED_FOLLOWING.code: 1 << 3,
    errors.SYNC_CYCLE.code: 1 << 5,
    errors.GUARDING.code: 1 << 5,
    errors.PROCEDURE.code: 1 << 7,
    errors.STOP_FAILED.code: 1 << 7,
    errors.MOTOR_TEMPERATURE.code: 1 << 13,
    errors.OVERCURRENT.code: 1 << 15,
    errors.OVERVOLTAGE.code: 0b010 << 16,
    errors.MOTOR_BRAKE.code: 0b111 << 16,
    errors.UNDERVOLTAGE.code: 1 << 20,
}
_PHASE_ORDER = {1: 0, -1: 1}


#: 0x30FD / 0x60FD bits 16–21 / 0x5F00: INPUT0 (LS+), INPUT1 (LS−), INHIBIT, INDEX, CAPTURE, LOW SPEED
LS_PLUS, LS_MINUS, INHIBIT = 1 << 0, 1 << 1, 1 << 2
PHYSICAL_SHIFT, PHYSICAL_INPUTS = 16, 0x3F
WIRING = (0x5F00, 0)
#: the input functions of 0x60FD a dedicated input gives: LS+ → bit 1 (positive limit), LS− → bit 0, INHIBIT → bit 3
_DEDICATED = ((LS_PLUS, 1 << 1), (LS_MINUS, 1 << 0), (INHIBIT, 1 << 3))


class Cd1kBehaviour(DriveBehaviour):
    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        if WIRING in self.store:
            self.store.on_write(*WIRING, self._wired)

    def _wired(self, index: int, sub: int, value: Value) -> None:
        """The test bench's wiring is hardware: it is kept through a warm reset."""
        self.store.set_factory(index, sub, value)

    def input_word(self) -> tuple[int, int]:
        """The CD1-k's six inputs (docs/io.md): the plant's limit switches are wired to LS+ and LS−, the test bench
        (0x5F00, 1 = active) may activate any input.  An input keeps its function only where 0x30FD has its bit
        (1 = dedicated, the factory 0x3F); a freed input shows in 0x60FD bits 16–21 and does nothing else."""
        physics = self.physics
        levels = int(self.p.get("sim_physical_inputs", 0)) & PHYSICAL_INPUTS
        levels |= (physics.positive_limit_active() and LS_PLUS) | (physics.negative_limit_active() and LS_MINUS)
        dedicated = levels & int(self.p.get("input_mask", PHYSICAL_INPUTS))
        functions = (physics.home_switch_active() and 1 << 2) | sum(bit for line, bit in _DEDICATED if dedicated & line)
        return functions | levels << PHYSICAL_SHIFT, 0xFFFF | PHYSICAL_INPUTS << PHYSICAL_SHIFT

    def read_units(self) -> UnitScaling:
        increments = float(self.p.get("encoder_increments", 0)) or float(self.physics.counts_per_turn)
        return UnitScaling(increments)

    def set_hardware_data(self) -> None:
        """Also the drive's current rating 6510h/4 (0.01 A, read-only hardware data the dictionary gives no value):
        the plant's peak current, the rating the currents' shares are taken of."""
        super().set_hardware_data()
        address = self.profile.address("drive_rating")
        if address is not None and address in self.store and not self.store.od[address].default_for(self.store.node_id):
            self.store.set_factory(address[0], address[1], round(self.plant.peak_current * 100))
            self.snapshot()

    def _measurement_functions(self) -> dict[str, Callable[[], int]]:
        """0x6078 in ‰ of the drive's current rating 6510h/4, as its dictionary gives it (docs/devices.md §9)."""
        functions = super()._measurement_functions()
        functions["current_actual"] = lambda: _clamp_i16(1000.0 * self._current_filter / self.drive_max_current)
        return functions

    def read_currents(self) -> tuple[float, float, float]:
        rating = float(self.p.get("drive_rating", 0)) * 0.01 or self.plant.peak_current
        maximum = float(self.p.get("max_current_share", FULL_SCALE)) / FULL_SCALE * rating or rating
        rated = float(self.p.get("rated_current_share", FULL_SCALE // 2)) / FULL_SCALE * rating or rating / 2
        return rating, rated, maximum

    def stop_current(self) -> float:
        """0x3301: 0x3FFF = 100 % of the drive rating."""
        return float(self.p.get("stop_current_limit", FULL_SCALE)) / FULL_SCALE * self.drive_max_current

    def homing_current(self) -> float:
        """0x309C: 0x3FFF = 100 % of the max current 0x6510,5."""
        return float(self.p.get("homing_current_limit", 0x400)) / FULL_SCALE * self.max_current

    def phase_sign_of(self, value: int) -> int:
        return -1 if value == 1 else 1

    def phase_value(self, sign: int) -> int:
        return _PHASE_ORDER[1 if sign > 0 else -1]

    def apply_commissioning(self) -> None:
        """Shares of the drive rating instead of mA; then the common values (commutation, gains)."""
        rating = float(self.p.get("drive_rating", 0)) * 0.01
        if rating > 0:
            plant = self.plant
            self.write("max_current_share", min(FULL_SCALE, round(plant.peak_current / rating * FULL_SCALE)))
            self.write("rated_current_share", min(FULL_SCALE // 2, round(plant.stall_current / rating * FULL_SCALE)))
            self.write("max_motor_speed", min(25000, plant.max_speed_rpm))
        super().apply_commissioning()

    def error_inhibited(self, error: DriveError) -> bool:
        return False

    def fault_reaction(self, error: DriveError) -> int:
        bit = _ERROR_BITS.get(error.code, 0)
        if bit & int(self.p.get("fault_reaction_stop3", 0)):
            return STOP_CURRENT_LIMIT
        if bit & int(self.p.get("fault_reaction_stop1", 0)):
            return STOP_SLOW_DOWN_RAMP
        return STOP_NONE

    def send_emergency(self, error: DriveError) -> None:
        """EMCY bytes 3–6 carry the 0x3020 drive error code (LSB first)."""
        value = self._error_bits()
        self.events.emergency(error.cia_code, value & 0xFF, (value >> 8).to_bytes(3, "little"))

    def _error_bits(self) -> int:
        value = 0
        for code in self.active_errors:
            value |= _ERROR_BITS.get(code, 0)
        return value

    def _publish_errors(self, latest: DriveError | None) -> None:
        self.write("error_bits", self._error_bits())
        self.write("error_code", latest.cia_code if latest else 0)
