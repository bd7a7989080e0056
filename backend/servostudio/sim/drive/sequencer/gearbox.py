"""The GEAR sequence's gearbox function (manual §3.2.4.3) and its master: the master input source 0x3910, which
may point at the virtual master 0x3906 (§3.2.4.2) or at any object a PDO fills (another drive's position).

The simulated drive has no second sensor input (encoder input 0x3129), so a master comes from the virtual master
or the bus. Slave position = ratio × master travel, ratio = numerator / denominator of the ratio set 0x3921 the
sequence's Config selects, times Factor / 32768 (sub 26; 0 = no factor), negative with "reverse direction".
Modelled: coupling mode 0 (speed ramp, the distance lost while ramping is not caught up), SyncDtn, exit modes
slowdown and immediate. Not modelled: coupling modes 1 and 2 (MasterDtn / SlaveDtn), trigger on a logic input,
start relative to a master modulo, ratio modulation, forward only.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import TYPE_CHECKING

from servostudio.od.model import Value
from servostudio.sim.drive.loops import time_constant_alpha
from servostudio.sim.drive.sequencer.motions import Carry, Motion, Reference, ramp_rate
from servostudio.sim.drive.sequencer.phases import CRUISE, DECEL, HOLD, NONE
from servostudio.sim.drive.sequencer.record import SequenceRecord

if TYPE_CHECKING:
    from servostudio.sim.drive.behaviour import DriveBehaviour
    from servostudio.sim.objects import ObjectStore

VIRTUAL_MASTER_SPEED = (0x3902, 0)
VIRTUAL_MASTER_ACCELERATION = (0x3903, 0)
VIRTUAL_MASTER_OUTPUT = (0x3906, 0)
MASTER_SOURCE = (0x3910, 0)
RATIO_SETS = 0x3921
EXIT_IMMEDIATE = 0x0001
RATIO_SET_2 = 0x0100
REVERSE = 0x2000
FACTOR_ONE = 32768
_I32_SPAN = 1 << 32


def wrap_i32(value: float) -> int:
    number = round(value) % _I32_SPAN
    return number - _I32_SPAN if number >= _I32_SPAN // 2 else number


class VirtualMaster:
    """0x3906: a position that ramps at 0x3903 (user units/s², 0 = at once) to the speed 0x3902 and keeps it.

    It is computed from the drive's time whenever it is read, from the state at the last write of 0x3902/0x3903:
    free between reads, and running in every operation mode as on the drive.
    """

    def __init__(self, drive: DriveBehaviour) -> None:
        self.drive = drive
        store = drive.store
        self._origin = (0.0, 0.0, 0.0)  # time, position, speed when the profile last changed
        self.speed = float(store.get(*VIRTUAL_MASTER_SPEED))
        self.acceleration = float(store.get(*VIRTUAL_MASTER_ACCELERATION))
        store.on_write(*VIRTUAL_MASTER_SPEED, self._speed_written)
        store.on_write(*VIRTUAL_MASTER_ACCELERATION, self._acceleration_written)
        store.on_read(*VIRTUAL_MASTER_OUTPUT, lambda index, sub: wrap_i32(self.position()))

    def position(self) -> float:
        return self._state(self.drive.time)[0]

    def reset(self) -> None:
        """Power-on (warm reset): at 0, standing, with the speed and acceleration the drive now holds."""
        store = self.drive.store
        self._origin = (self.drive.time, 0.0, 0.0)
        self.speed = float(store.get(*VIRTUAL_MASTER_SPEED))
        self.acceleration = float(store.get(*VIRTUAL_MASTER_ACCELERATION))

    def _speed_written(self, index: int, sub: int, value: Value) -> None:
        self._rebase()
        self.speed = float(value)

    def _acceleration_written(self, index: int, sub: int, value: Value) -> None:
        self._rebase()
        self.acceleration = float(value)

    def _rebase(self) -> None:
        now = self.drive.time
        position, speed = self._state(now)
        self._origin = (now, position, speed)

    def _state(self, now: float) -> tuple[float, float]:
        """Position and speed at `now`: the ramp from the origin's speed to `speed`, then constant speed."""
        start, position, speed = self._origin
        elapsed = now - start
        change = self.speed - speed
        ramp = abs(change) / self.acceleration if self.acceleration > 0 else 0.0
        if elapsed >= ramp:
            ramp_distance = 0.5 * (speed + self.speed) * ramp
            return position + ramp_distance + self.speed * (elapsed - ramp), self.speed
        rate = math.copysign(self.acceleration, change)
        return position + speed * elapsed + 0.5 * rate * elapsed * elapsed, speed + rate * elapsed


class MasterInput:
    """The master 0x3910 points at (index << 16 | sub << 8), read as any bus read would (computed objects too);
    `advance` gives its travel since the last call, across an I32 wrap. No valid source: a master at rest."""

    def __init__(self, store: ObjectStore) -> None:
        pointer = int(store.get(*MASTER_SOURCE))
        variable = store.od.get(pointer >> 16 & 0xFFFF, pointer >> 8 & 0xFF) if pointer else None
        self._read: Callable[[], Value] = store.value_reader(variable) if variable is not None else (lambda: 0)
        self._last = int(self._read())

    def advance(self) -> int:
        value = int(self._read())
        travel = wrap_i32(value - self._last)
        self._last = value
        return travel


def gear_ratio(store: ObjectStore, record: SequenceRecord) -> float:
    """Slave user units per master unit: the ratio set Config selects (bit 8), the Factor, the direction."""
    numerator = 3 if record.configuration & RATIO_SET_2 else 1
    ratio = float(store.get(RATIO_SETS, numerator)) / float(store.get(RATIO_SETS, numerator + 1))
    if record.analog2:
        ratio *= record.analog2 / FACTOR_ONE
    return -ratio if record.configuration & REVERSE else ratio


class GearMotion(Motion):
    """GEAR: the slave speed goes in Accel ms from where it was to ratio × the master speed, then the slave
    follows ratio × the master's travel (CRUISE = in gear) until it has moved SyncDtn (0: until an end condition
    or a stop); it then slows down in Accel ms (DECEL, HOLD), or with the immediate exit mode ends at speed.

    The master speed is its travel per control period through a 5 ms low-pass (an integer master moves by whole
    units, so single periods jitter); in gear the slave position follows the travel itself, so no distance is
    lost to the filter.
    """

    MASTER_SPEED_FILTER = 5e-3

    def __init__(self, drive: DriveBehaviour, record: SequenceRecord, carry: Carry) -> None:
        super().__init__(drive)
        self.record = record
        self.reference = Reference(drive.dt, carry)
        self.master = MasterInput(drive.store)
        self.ratio = gear_ratio(drive.store, record) * drive.units.to_rad(1.0)  # slave rad per master unit
        self.remaining = abs(drive.units.to_rad(record.speed2)) or math.inf  # SyncDtn: slave travel in gear
        self.ramp_time = record.acceleration_time / 1000.0
        self.start_speed = carry.velocity
        self.slave_speed = 0.0
        self.elapsed = 0.0
        self.rate = math.inf
        self._alpha = time_constant_alpha(self.MASTER_SPEED_FILTER, drive.dt)
        self.stage: Callable[[float], int] = self._couple

    def _phases(self) -> int:
        travel = self.ratio * self.master.advance()
        self.slave_speed += self._alpha * (travel / self.dt - self.slave_speed)
        phases = self.stage(travel)
        self.reference.follow(self.loops)
        return phases

    def _couple(self, travel: float) -> int:
        self.elapsed += self.dt
        fraction = min(1.0, self.elapsed / self.ramp_time) if self.ramp_time else 1.0
        self.reference.run_at(self.start_speed + (self.slave_speed - self.start_speed) * fraction)
        if fraction < 1.0:
            return NONE
        self.stage = self._geared
        return CRUISE

    def _geared(self, travel: float) -> int:
        self.reference.advance(travel, self.slave_speed)
        self.remaining -= abs(travel)
        return self._exit() if self.remaining <= 0.0 else NONE

    def _exit(self) -> int:
        if self.record.configuration & EXIT_IMMEDIATE:
            self.arrived = True
            self.stage = self._coast
            return NONE
        self.reference.velocity = self.slave_speed
        self.rate = ramp_rate(self.slave_speed, 0.0, self.record.acceleration_time)
        self.stage = self._slow_down
        return DECEL

    def _slow_down(self, travel: float) -> int:
        if not self.reference.ramp_to(0.0, self.rate):
            return NONE
        self.arrived = True
        self.stage = self._coast
        return HOLD

    def _coast(self, travel: float) -> int:
        self.reference.coast()
        return NONE

    def end_early(self) -> Motion:
        if self.stage in (self._couple, self._geared):
            self._pending |= self._exit()
        return self
