"""Manual homing of the TTA-PRO, started by a rising edge of CW11 and configured by PNU 766 (TTA-PRO Profibus
Communication Profile, Chapter 3, L1732-1761): bit 3 direction (1 = negative), bit 4 search the home switch,
bit 5 search the marker (index) pulse, bit 6 move onto the home position once found (else stop there), bit 7 set
the position counter to PNU 768 at the home position. Speed and ramps are the manual-motion ones (760-762).

The manual does not say what a limit switch does to the search; here the search reverses once at a limit switch
and fails at the second one (error 4, homing time-out, is the code the drive has for a failed homing).
"""

from __future__ import annotations

import enum
import math

from servostudio.sim.profibus.axis import Axis

DIRECTION_NEGATIVE = 1 << 3
WITH_SWITCH = 1 << 4
WITH_MARKER = 1 << 5
MOVE_TO_HOME = 1 << 6
RESET_COUNTER = 1 << 7
FAR = 1e6
"""rad: the target of a search move (it ends on a signal, never there)."""


class Phase(enum.Enum):
    SWITCH = "searching the home switch"
    MARKER = "searching the marker pulse"
    FINISHING = "stopping or moving onto the home position"
    DONE = "home found"
    FAILED = "failed"


class ManualHoming:
    def __init__(self, axis: Axis, configuration: int, speed: float, accel: float, decel: float) -> None:
        self.axis = axis
        self.configuration = configuration
        self.speed, self.accel, self.decel = speed, accel, decel
        self.direction = -1.0 if configuration & DIRECTION_NEGATIVE else 1.0
        self.reversed = False
        self.home: float | None = None
        self.phase = Phase.SWITCH
        if configuration & WITH_SWITCH:
            self._search()
        else:
            self._after_switch()

    @property
    def resets_counter(self) -> bool:
        return bool(self.configuration & RESET_COUNTER)

    @property
    def finished(self) -> bool:
        return self.phase in (Phase.DONE, Phase.FAILED)

    def step(self) -> None:
        """One positioner cycle."""
        if self.phase is Phase.SWITCH:
            self._step_switch()
        elif self.phase is Phase.MARKER:
            self._step_marker()
        elif self.phase is Phase.FINISHING and not self.axis.moving:
            self.phase = Phase.DONE

    def _search(self) -> None:
        self.axis.move_to(self.axis.position + self.direction * FAR, self.speed, self.accel, self.decel)

    def _step_switch(self) -> None:
        physics = self.axis.physics
        if physics.home_switch_active():
            self._after_switch()
        elif self._at_limit(physics):
            self._reverse()

    def _after_switch(self) -> None:
        if self.configuration & WITH_MARKER:
            self.phase = Phase.MARKER
            self.axis.physics.index_seen = False
            if not self.axis.moving:
                self._search()
        else:
            self._found(self.axis.position)

    def _step_marker(self) -> None:
        physics = self.axis.physics
        if physics.index_seen:
            self._found(physics.counter_turns(physics.index_turns) * 2.0 * math.pi)
        elif self._at_limit(physics):
            self._reverse()

    def _at_limit(self, physics) -> bool:
        if self.direction > 0:
            return physics.positive_limit_active()
        return physics.negative_limit_active()

    def _reverse(self) -> None:
        if self.reversed:
            self.axis.brake_at_limit()
            self.phase = Phase.FAILED
            return
        self.reversed = True
        self.direction = -self.direction
        self._search()

    def _found(self, home: float) -> None:
        self.home = home
        self.phase = Phase.FINISHING
        if self.configuration & MOVE_TO_HOME:
            self.axis.move_to(home, self.speed, self.accel, self.decel)
        elif self.axis.moving:
            self.axis.ramp_stop(self.decel)
