"""The TTA-PRO control word as the simulated drive reads it (TTA-PRO Profibus Communication Profile, Chapter 2
§2.1, §2.5, §3.1, L427-672).

Bits 0-3 and 7 are the enabling commands; they map onto the CiA 402 commands of the shared state machine
(`servostudio.sim.drive.statemachine`): OFF1 (bit 0 = 0) is a shutdown with a ramp, OFF2 (bit 1 = 0) disables the
voltage, OFF3 (bit 2 = 0) is a quick stop, bit 3 enables operation. The priority differs from CiA 402: the manual
puts OFF1 before OFF3 ("OFF2 has a priority over OFF1 which has a priority over OFF3", L596-599).
"""

from __future__ import annotations

from servostudio.sim.drive.statemachine import Command

ON = 0x0001
NO_OFF2 = 0x0002
NO_OFF3 = 0x0004
ENABLE_OPERATION = 0x0008
NO_STOP = 0x0010
NO_INTERMEDIATE_STOP = 0x0020
RUN_SEQUENCE = 0x0040
FAULT_ACKNOWLEDGE = 0x0080
JOG_PLUS = 0x0100
JOG_MINUS = 0x0200
PROFIBUS_CONTROL = 0x0400
HOMING = 0x0800
ABSOLUTE_MOVE = 0x1000
RELATIVE_MOVE = 0x2000
GEARING = 0x4000


def enabling_command(control_word: int) -> Command:
    """The command bits 0-3 give, OFF2 first, then OFF1, then OFF3."""
    if not control_word & NO_OFF2:
        return Command.DISABLE_VOLTAGE
    if not control_word & ON:
        return Command.SHUTDOWN
    if not control_word & NO_OFF3:
        return Command.QUICK_STOP
    if control_word & ENABLE_OPERATION:
        return Command.ENABLE_OPERATION
    return Command.SWITCH_ON


class Edges:
    """Bit changes of the control word between two positioner cycles."""

    def __init__(self) -> None:
        self.previous = 0
        self.toggled = 0
        self.rising = 0

    def update(self, control_word: int) -> None:
        self.toggled = control_word ^ self.previous
        self.rising = self.toggled & control_word
        self.previous = control_word
