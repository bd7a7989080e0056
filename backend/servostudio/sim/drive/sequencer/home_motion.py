"""The HOME sequence: "the Home sequence runs like in Homing Mode" (manual L9846–9884), so it runs the drive's own
homing methods (sim/drive/homing.py through `HomingMode`) with the sequence's parameters."""

from __future__ import annotations

from typing import TYPE_CHECKING

from servostudio.sim.drive.modes import HomingMode
from servostudio.sim.drive.sequencer.motions import Carry, Motion
from servostudio.sim.drive.sequencer.phases import HOLD, INPOS, NONE
from servostudio.sim.drive.sequencer.record import SequenceRecord

if TYPE_CHECKING:
    from servostudio.sim.drive.behaviour import DriveBehaviour

RETURN_TO_HOME = 1
"""HOME configuration (sub 21) bit 0: move back onto the reference once found, like 0x309D = 1."""


class SequenceHoming(HomingMode):
    """Homing Mode with a HOME sequence's parameters in place of the drive's homing objects: Method (sub 22) for
    0x6098, Speed / Speed2 (15 / 16) for 0x6099, the acceleration that reaches Speed in Accel ms (19) for 0x609A,
    the home offset (13) for 0x607C, the return option (21) for 0x309D and, for methods −1..−4, the current limit
    Torque (25, ‰ of 0x6075) for 0x309C. Accel 0 and Torque 0 keep the drive's 0x609A and 0x309C."""

    def __init__(self, drive: DriveBehaviour, record: SequenceRecord) -> None:
        super().__init__(drive)
        self.settings = {
            "homing_method": float(record.configuration2),
            "homing_speed_fast": float(abs(record.speed)),
            "homing_speed_slow": float(abs(record.speed2)),
            "home_offset": float(record.position),
            "end_on_home": float(record.configuration & RETURN_TO_HOME),
        }
        if record.acceleration_time and record.speed:
            self.settings["homing_acceleration"] = abs(record.speed) / (record.acceleration_time / 1000.0)
        self.limit = abs(record.analog) / 1000.0 * drive.rated_current if record.analog else None

    def setting(self, name: str, default: float) -> float:
        if name in self.settings:
            return self.settings[name]
        return super().setting(name, default)

    def current_limit(self) -> float:
        if self.uses_current_limit and self.limit is not None:
            return self.limit
        return super().current_limit()


class HomeMotion(Motion):
    """HOME: HOLD once the reference is found (and, with the return option, reached), INPOS when the position is
    within 0x6067 of the reference (at once with 0x6067 = 0). A homing error fails the sequence; an end condition
    or a stop drops the method and ramps the axis to a stop (HOLD)."""

    uses_limit_switches = True

    def __init__(self, drive: DriveBehaviour, record: SequenceRecord, carry: Carry) -> None:
        super().__init__(drive)
        self.window = float(drive.p.get("position_window", 0))
        homing = self.homing = SequenceHoming(drive, record)
        homing.enter()
        homing.ramp.velocity = carry.velocity
        homing.start()
        self._interrupted = False

    def _phases(self) -> int:
        homing = self.homing
        homing.step()
        if homing.error:
            self.failed = True
            return NONE
        if self._interrupted:
            self.arrived = homing.ramp.velocity == 0.0
            return HOLD if self.arrived else NONE
        if not homing.attained:
            return NONE
        return HOLD | self._in_position()

    def _in_position(self) -> int:
        loops = self.loops
        if self.window > 0 and abs(self.drive.units.to_user(loops.position_ref - loops.position)) > self.window:
            return NONE
        self.arrived = True
        return INPOS

    def end_early(self) -> Motion:
        self.homing.interrupt()
        self._interrupted = True
        return self

    def current_limit(self) -> float:
        return self.homing.current_limit()
