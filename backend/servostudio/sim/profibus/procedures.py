"""Procedure PNUs: a PKW write starts them, the reply's PWE reads 0 while they run, then 1 (done) or 2 (error)
(TTA-PRO Profibus Communication Profile, Chapter 1 §3.2, L346-357).

The simulator carries out the ones it can model faithfully: 729 (save the E parameters), 780 / 781 (sequence
EEPROM read / write and checksum), 894 (motor feedback programming: the selection 890-893/898 it applied is
recorded). The others (auto-phasing, auto-tuning, encoder output programming, absolute-encoder and cogging
procedures) need models this stage does not have; they are refused with PKW error 18 instead of pretending to
succeed. A procedure the manual runs "with disabled positioner" (729, 894, …) is refused with error 17 while enabled.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from servostudio.sim.profibus.parameters import NOT_IN_THIS_STATE, OTHER_ERROR, ParameterMemory, PkwRefusal

RUNNING = 0
DONE = 1
FAILED = 2


@dataclass(frozen=True)
class Procedure:
    """What a procedure does with the written value, and how long it takes (virtual seconds)."""

    duration: float
    action: Callable[[int], bool]
    """value -> success; runs when the duration has elapsed."""


class ProcedureRunner:
    def __init__(self, memory: ParameterMemory, enabled: Callable[[], bool]) -> None:
        self.memory = memory
        self._enabled = enabled
        self._known: dict[int, Procedure] = {}
        self._status: dict[int, int] = {}
        self._running: dict[int, tuple[float, int]] = {}  # pnu -> (time left, value)

    def define(self, pnu: int, procedure: Procedure) -> None:
        self._known[pnu] = procedure

    def start(self, pnu: int, value: int) -> None:
        """Checks the preconditions the manual gives; a PkwRefusal refuses the instruction."""
        procedure = self._known.get(pnu)
        if procedure is None:
            raise PkwRefusal(OTHER_ERROR, f"procedure PNU {pnu} is not simulated")
        if self.memory.parameters[pnu].disabled_only and self._enabled():
            raise PkwRefusal(NOT_IN_THIS_STATE, f"PNU {pnu} runs with the positioner disabled only")
        self._status[pnu] = RUNNING
        self._running[pnu] = (procedure.duration, value)

    def status(self, pnu: int) -> int:
        return self._status.get(pnu, DONE)

    def step(self, dt: float) -> None:
        for pnu, (left, value) in list(self._running.items()):
            if left > dt:
                self._running[pnu] = (left - dt, value)
                continue
            del self._running[pnu]
            self._status[pnu] = DONE if self._known[pnu].action(value) else FAILED
