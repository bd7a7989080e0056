"""The status word ZSW (PZD1 of the PPO read) of the simulated TTA-PRO (TTA-PRO Profibus Communication Profile,
Chapter 2 §2.3 and §3.3, L494-535, L684-720).

Bits 0-3 and 6 come from the enabling state; bit 4 "no OFF2" and bit 5 "no OFF3" follow the control word (bit 5
also drops while the OFF3 stop runs); bit 8 drops on a following error and while a limit switch is active (the
drive stays enabled, no fault). Bits 10-14 exist in position mode only; bit 15 (speed reached) in every mode.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from servostudio.sim.drive.statemachine import State
from servostudio.sim.profibus import control_word as cw
from servostudio.sim.profibus.drive_units import TWO_PI
from servostudio.sim.profibus.modes import POSITIONER

if TYPE_CHECKING:
    from servostudio.sim.profibus.positioner import TtaProDrive

READY_FOR_ENABLING = 0x0001
NO_OFF2 = 0x0010
NO_OFF3 = 0x0020
WARNING = 0x0080
NO_FOLLOWING_ERROR = 0x0100
PROFIBUS_CONTROL = 0x0200
POSITION_REACHED = 0x0400
HOME_FOUND = 0x0800
ACKNOWLEDGE = 0x1000
MOTOR_STOPPED = 0x2000
SPEED_REACHED = 0x8000
INPOS_WINDOW = 1 << 13
"""PNU 742 bit 13: the INPOS window (757) is active."""
SPEED_TOLERANCE = 0.02
"""Speed reached within 2 % of the maximum speed (the manual gives no window)."""
WARNING_SOURCES = ((1 << 0, "software_limit"), (1 << 3, "i2t"))
"""PNU 899 bits selecting what sets ZSW7 (motor / drive temperature, bits 1 and 2, are not modelled)."""


def status_word(drive: TtaProDrive) -> int:
    control = drive.words[0]
    word = drive.state_bits
    if not drive.enable_input:
        word &= ~READY_FOR_ENABLING
    if control & cw.NO_OFF2:
        word |= NO_OFF2
    if control & cw.NO_OFF3 and drive.device.state is not State.QUICK_STOP_ACTIVE:
        word |= NO_OFF3
    if _warning(drive):
        word |= WARNING
    if not (drive.following_error or drive.limit_switch):
        word |= NO_FOLLOWING_ERROR
    if drive.profibus_control:
        word |= PROFIBUS_CONTROL
    if _speed_reached(drive):
        word |= SPEED_REACHED
    if drive.mode == POSITIONER:
        word |= _positioner_bits(drive)
    return word


def _warning(drive: TtaProDrive) -> bool:
    selected = drive.memory.get(899)
    present = {"software_limit": drive.software_limit, "i2t": drive.i2t.warning}
    return any(selected & bit and present[name] for bit, name in WARNING_SOURCES)


def _speed_reached(drive: TtaProDrive) -> bool:
    axis = drive.axis
    wanted = axis.profile.velocity if drive.mode == POSITIONER else drive.speed_target
    return abs(axis.speed - wanted) <= SPEED_TOLERANCE * drive.units.max_speed


def _positioner_bits(drive: TtaProDrive) -> int:
    motions, axis = drive.motions, drive.axis
    window_enabled = bool(drive.memory.get(742) & INPOS_WINDOW)
    error = abs(axis.profile.target - axis.position) / TWO_PI * drive.units.increments_per_turn
    in_window = not window_enabled or error <= drive.memory.get(757)
    bits = (
        (motions.active is None and not axis.moving and in_window, POSITION_REACHED),
        (motions.home_found, HOME_FOUND),
        (motions.acknowledge, ACKNOWLEDGE),
        (window_enabled and axis.stopped, MOTOR_STOPPED),
    )
    return sum(bit for active, bit in bits if active)
