"""Position-mode commands of the control word while the operation is enabled (TTA-PRO Profibus Communication
Profile, Chapter 2 §2.1-2.6, L427-648, §4.2-4.3, L798-822): stop (CW4 = 0), intermediate stop (CW5 = 0), jog
(CW8 / CW9), homing (CW11 rising edge), absolute and relative moves (each edge of CW12 / CW13).

Movements are mutually exclusive: a command arriving while another movement runs is ignored, and ZSW12 toggles
only for a command that was accepted. Sequences (CW6) are not simulated in this stage.
"""

from __future__ import annotations

from servostudio.sim.profibus import control_word as cw
from servostudio.sim.profibus.axis import Axis
from servostudio.sim.profibus.drive_units import DriveUnits
from servostudio.sim.profibus.homing import FAR, ManualHoming, Phase
from servostudio.sim.profibus.parameters import ParameterMemory

JOG_BITS = cw.JOG_PLUS | cw.JOG_MINUS
SPEED_MODULATION = 1 << 9
"""PNU 742 bit 9: moves run at PNU 714 % of their programmed speed."""
FULL_SCALE = 32767


class PositionerMotions:
    def __init__(self, axis: Axis, units: DriveUnits, memory: ParameterMemory) -> None:
        self.axis = axis
        self.units = units
        self.memory = memory
        self.active: str | None = None
        """"move", "jog" or "homing" while one runs."""
        self.homing: ManualHoming | None = None
        self.acknowledge = False
        self.home_found = False
        self.homing_failed = False
        self._paused: tuple[float, float, float, float] | None = None
        self._stopping = False

    def cancel(self) -> None:
        """The movement ends without completing (disable, stop, limit switch)."""
        self.active = None
        self.homing = None
        self._paused = None
        self._stopping = False

    def run(self, control_word: int, toggled: int, rising: int) -> None:
        """One positioner cycle in Operation enabled."""
        if not control_word & cw.NO_STOP:
            self._stop_at_maximum()
            return
        if not control_word & cw.NO_INTERMEDIATE_STOP:
            self._pause()
            return
        self._resume()
        self._jog(control_word)
        if self.active is None:
            self._start(toggled, rising)
        self._progress()

    # -- stops --------------------------------------------------------------------------------------------------

    def _stop_at_maximum(self) -> None:
        if self.active is not None or self.axis.moving:
            self.axis.brake_at_limit()
            self.cancel()

    def _pause(self) -> None:
        if self.active is None or self._paused is not None:
            return
        profile = self.axis.profile
        self._paused = (profile.target, profile.max_velocity, profile.accel, profile.decel)
        self.axis.ramp_stop(self._ramp(765))

    def _resume(self) -> None:
        if self._paused is not None:
            self.axis.move_to(*self._paused)
            self._paused = None

    # -- movements ----------------------------------------------------------------------------------------------

    def _jog(self, control_word: int) -> None:
        bits = control_word & JOG_BITS
        if self.active is None and bits in (cw.JOG_PLUS, cw.JOG_MINUS):
            self.active = "jog"
            direction = 1.0 if bits == cw.JOG_PLUS else -1.0
            target = self.axis.profile.position + direction * self.units.direction * FAR
            self.axis.move_to(target, self._speed(763), self._ramp(764), self._ramp(765))
        elif self.active == "jog" and bits not in (cw.JOG_PLUS, cw.JOG_MINUS) and not self._stopping:
            self._stopping = True
            self.axis.ramp_stop(self._ramp(765))

    def _start(self, toggled: int, rising: int) -> None:
        if rising & cw.HOMING:
            self._start_homing()
        elif toggled & cw.ABSOLUTE_MOVE:
            self._move(self.units.position_rad(self.memory.get(767)))
        elif toggled & cw.RELATIVE_MOVE:
            self._move(self.axis.profile.position + self.units.distance_rad(self.memory.get(767)))

    def _move(self, target: float) -> None:
        self.active = "move"
        self.acknowledge = not self.acknowledge
        self.axis.move_to(target, self._speed(760), self._ramp(761), self._ramp(762))

    def _start_homing(self) -> None:
        self.active = "homing"
        self.acknowledge = not self.acknowledge
        self.home_found = False
        self.homing = ManualHoming(self.axis, self.memory.get(766), self._speed(760), self._ramp(761), self._ramp(762))

    def _progress(self) -> None:
        if self.active == "homing" and self.homing is not None:
            self._progress_homing(self.homing)
        elif self.active is not None and not self.axis.moving:
            self.active = None
            self._stopping = False

    def _progress_homing(self, homing: ManualHoming) -> None:
        homing.step()
        if not homing.finished:
            return
        if homing.phase is Phase.DONE and homing.home is not None:
            self._home_at(homing.home, homing.resets_counter)
        else:
            self.homing_failed = True
        self.cancel()

    def _home_at(self, home: float, reset: bool) -> None:
        self.home_found = True
        if reset:
            self.units.offset += self.memory.get(768) - self.units.position(home)

    # -- parameters ---------------------------------------------------------------------------------------------

    def _speed(self, pnu: int) -> float:
        speed = self.units.speed_rad(self.memory.get(pnu))
        if self.memory.get(742) & SPEED_MODULATION:
            speed *= self.memory.get(714) / FULL_SCALE
        return speed

    def _ramp(self, pnu: int) -> float:
        return self.units.ramp(self.memory.get(pnu))
