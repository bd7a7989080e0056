"""Homing methods of the XtrapulsPac (manual §3.2.3.4): CiA 402 methods 1–14, 17–30, 33–35 and the mechanical
stop methods −1..−4, run against the simulated limit switches, home switch, index pulse and hard stops.

The drive only sees its inputs: a method is a sequence of moves "at speed s in direction d until <signal
changes>". The home switch is a cam (active between two positions); "negative side" / "positive side" is its
lower / upper edge. Exterior means the index is searched outside the cam, interior inside (manual table,
worked example of method 8). A move that runs into the limit switch of its direction reverses (methods 7–14
and the home-switch search of 3–6); a stall at a hard stop where none is expected is a homing error.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

LOW_EDGE = -1
HIGH_EDGE = 1
FAST = 1
SLOW = 2


class HomingStatus(enum.Enum):
    IDLE = "idle"
    RUNNING = "running"
    FOUND = "found"
    ERROR = "error"


@dataclass(frozen=True)
class SwitchMethod:
    """A method using the home switch: which edge, direction of the final approach, first move, index or not."""

    edge: int
    final_direction: int
    first_direction: int
    index: bool


@dataclass
class HomingInputs:
    negative_limit: bool
    positive_limit: bool
    home_switch: bool
    index_seen: bool
    index_position: float
    stalled: bool
    position: float


_HOME_SWITCH_METHODS: dict[int, SwitchMethod] = {
    3: SwitchMethod(LOW_EDGE, -1, +1, True),
    4: SwitchMethod(LOW_EDGE, +1, +1, True),
    5: SwitchMethod(HIGH_EDGE, +1, -1, True),
    6: SwitchMethod(HIGH_EDGE, -1, -1, True),
    7: SwitchMethod(LOW_EDGE, -1, +1, True),
    8: SwitchMethod(LOW_EDGE, +1, +1, True),
    9: SwitchMethod(HIGH_EDGE, -1, +1, True),
    10: SwitchMethod(HIGH_EDGE, +1, +1, True),
    11: SwitchMethod(HIGH_EDGE, +1, -1, True),
    12: SwitchMethod(HIGH_EDGE, -1, -1, True),
    13: SwitchMethod(LOW_EDGE, +1, -1, True),
    14: SwitchMethod(LOW_EDGE, -1, -1, True),
}
for _method in range(19, 31):
    _base = _HOME_SWITCH_METHODS[_method - 16]
    _HOME_SWITCH_METHODS[_method] = SwitchMethod(_base.edge, _base.final_direction, _base.first_direction, False)

SUPPORTED_METHODS = frozenset({1, 2, 17, 18, 33, 34, 35, -1, -2, -3, -4} | set(_HOME_SWITCH_METHODS))


class Homing:
    """One homing run. `step()` returns (direction, speed class) to move with, or None to stand still."""

    def __init__(self, method: int) -> None:
        self.method = method
        self.status = HomingStatus.RUNNING if method in SUPPORTED_METHODS else HomingStatus.ERROR
        self.home_position = 0.0
        self.uses_current_limit = method in (-1, -2, -3, -4)
        self._phase = "start"
        self._direction = 0
        self._reversals = 0

    def step(self, inputs: HomingInputs) -> tuple[int, int] | None:
        if self.status is not HomingStatus.RUNNING:
            return None
        method = self.method
        if method == 35:
            self._found(inputs.position)
            return None
        if method in (33, 34):
            return self._index_only(inputs, -1 if method == 33 else +1)
        if method in (1, 2, 17, 18):
            return self._limit_switch(inputs, -1 if method in (1, 17) else +1, method in (1, 2))
        if method in (-1, -2, -3, -4):
            return self._hard_stop(inputs, -1 if method in (-1, -3) else +1, method in (-1, -2))
        return self._home_switch(inputs, _HOME_SWITCH_METHODS[method])

    # -- method families ----------------------------------------------------------------------------------------

    def _index_only(self, inputs: HomingInputs, direction: int) -> tuple[int, int] | None:
        if inputs.index_seen:
            self._found(inputs.index_position)
            return None
        if inputs.stalled or self._limit_ahead(inputs, direction):
            self._error()
            return None
        return direction, SLOW

    def _limit_switch(self, inputs: HomingInputs, towards: int, index: bool) -> tuple[int, int] | None:
        active = inputs.negative_limit if towards < 0 else inputs.positive_limit
        if self._phase == "start":
            self._phase = "seek" if not active else "leave"
        if self._phase == "seek":
            if active:
                self._phase = "leave"
            elif inputs.stalled:
                self._error()
                return None
            else:
                return towards, FAST
        if self._phase == "leave":
            if not active:
                if not index:
                    self._found(inputs.position)
                    return None
                self._phase = "index"
            else:
                return -towards, SLOW
        return self._index_after_edge(inputs, -towards)

    def _hard_stop(self, inputs: HomingInputs, towards: int, index: bool) -> tuple[int, int] | None:
        if self._phase == "start":
            self._phase = "seek"
        if self._phase == "seek":
            if not inputs.stalled:
                return towards, FAST
            if not index:
                self._found(inputs.position)
                return None
            self._phase = "index"
            self.uses_current_limit = False
        return self._index_after_edge(inputs, -towards)

    def _home_switch(self, inputs: HomingInputs, method: SwitchMethod) -> tuple[int, int] | None:
        if self._phase == "start":
            self._phase = "inside" if inputs.home_switch else "seek"
            self._direction = method.first_direction
        if self._phase == "seek":
            if inputs.home_switch:
                self._phase = "inside"
            else:
                if self._limit_ahead(inputs, self._direction):
                    self._reversals += 1
                    if self._reversals > 1:
                        self._error()
                        return None
                    self._direction = -self._direction
                if inputs.stalled:
                    self._error()
                    return None
                return self._direction, FAST
        outwards = method.final_direction if self._is_exterior(method) else -method.final_direction
        if self._phase == "inside":
            if inputs.home_switch:
                return outwards, SLOW if self._is_exterior(method) else FAST
            if self._is_exterior(method):
                if not method.index:
                    self._found(inputs.position)
                    return None
                self._phase = "index"
            else:
                self._phase = "back"
        if self._phase == "back":
            if not inputs.home_switch:
                return method.final_direction, SLOW
            if not method.index:
                self._found(inputs.position)
                return None
            self._phase = "index"
        return self._index_after_edge(inputs, method.final_direction)

    @staticmethod
    def _is_exterior(method: SwitchMethod) -> bool:
        """Exterior: the final approach leaves the cam (low edge going negative, high edge going positive)."""
        return method.final_direction == method.edge

    # -- shared steps ------------------------------------------------------------------------------------------

    def _index_after_edge(self, inputs: HomingInputs, direction: int) -> tuple[int, int] | None:
        if self._phase != "index_armed":
            self._phase = "index_armed"
            return direction, SLOW  # an index latched before the edge does not count
        if inputs.index_seen:
            self._found(inputs.index_position)
            return None
        if inputs.stalled or self._limit_ahead(inputs, direction):
            self._error()
            return None
        return direction, SLOW

    @staticmethod
    def _limit_ahead(inputs: HomingInputs, direction: int) -> bool:
        return inputs.positive_limit if direction > 0 else inputs.negative_limit

    def _found(self, position: float) -> None:
        self.home_position = position
        self.status = HomingStatus.FOUND

    def _error(self) -> None:
        self.status = HomingStatus.ERROR
