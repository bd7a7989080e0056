"""Drive errors and warnings of the XtrapulsPac manual (§3.2.1.4) that the simulated drive can raise.

Infranor code n (1–64) is bit n−1 of the 64-bit pair 0x3022,1 / 0x3022,2; each has a CiA 402 code for 0x603F and
the EMCY frame. Only the codes in STOP_2_3_ALLOWED may be given a ramp reaction through the 0x3025 masks; every
other error is a Stop 0 (power off at once, brake applied).
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class DriveError:
    code: int
    name: str
    cia_code: int

    @property
    def word(self) -> int:
        """0x3022 sub-index holding the bit (1 for codes 1–32, 2 for 33–64)."""
        return 1 if self.code <= 32 else 2

    @property
    def mask(self) -> int:
        return 1 << ((self.code - 1) % 32)


UNDERVOLTAGE = DriveError(3, "Undervoltage", 0x3220)
OVERVOLTAGE = DriveError(6, "Overvoltage", 0x3210)
OVERCURRENT = DriveError(18, "Overcurrent", 0x2310)
ENCODER_COUNTING = DriveError(19, "Encoder 1 counting error", 0x7305)
MOTOR_BRAKE = DriveError(27, "Motor brake error", 0x7120)
SPEED_FOLLOWING = DriveError(34, "Speed following error", 0x8400)
POSITION_FOLLOWING = DriveError(35, "Position following error", 0x8611)
SOFTWARE_LIMIT = DriveError(36, "Software position limit", 0x8680)
MOTOR_TEMPERATURE = DriveError(37, "Motor temperature error", 0x4290)
I2T = DriveError(38, "I2t error", 0x2350)
BUSY_TIMEOUT = DriveError(40, "Busy / operation timeout", 0xFFA0)
DRIVE_PARAMETERS_FILE = DriveError(42, "Drive parameters file error", 0x6320)
USER_PARAMETERS_FILE = DriveError(43, "User parameters / template file error", 0x6320)
SEQUENCE_FILE = DriveError(44, "Sequence file error", 0x6320)
SYNC_CYCLE = DriveError(49, "Fieldbus SYNC cycle error", 0x8780)
IP_UNDERFLOW = DriveError(50, "Fieldbus IP reference underflow/overflow", 0x8782)
GUARDING = DriveError(51, "Fieldbus guarding error", 0x8130)
STOP_FAILED = DriveError(60, "Stop operation failed", 0xFF10)
PROCEDURE = DriveError(64, "Procedure error", 0xFFA2)

CATALOGUE: dict[int, DriveError] = {
    e.code: e
    for e in (
        UNDERVOLTAGE,
        OVERVOLTAGE,
        OVERCURRENT,
        ENCODER_COUNTING,
        MOTOR_BRAKE,
        SPEED_FOLLOWING,
        POSITION_FOLLOWING,
        SOFTWARE_LIMIT,
        MOTOR_TEMPERATURE,
        I2T,
        BUSY_TIMEOUT,
        DRIVE_PARAMETERS_FILE,
        USER_PARAMETERS_FILE,
        SEQUENCE_FILE,
        SYNC_CYCLE,
        IP_UNDERFLOW,
        GUARDING,
        STOP_FAILED,
        PROCEDURE,
    )
}

STOP_2_3_ALLOWED = frozenset({34, 35, 36, 37, 38, 46, 49, 50, 51, 58})

# 0x3024 warning bits (warning code = bit + 1)
WARNING_LIMIT_SWITCH = 1 << 16
WARNING_I2T = 1 << 18
WARNING_UNDERVOLTAGE = 1 << 19
WARNING_MOTOR_TEMPERATURE = 1 << 21
WARNING_POSITION_LIMIT = 1 << 24
WARNING_PHASING_NOT_OK = 1 << 30

STOP_0 = 0
STOP_2 = 2
STOP_3 = 3


def stop_for(code: int, stop2_mask: int, stop3_mask: int) -> int:
    """Fault reaction of an error: Stop 3 wins over Stop 2 (the manual prefers it), else Stop 0."""
    if code not in STOP_2_3_ALLOWED:
        return STOP_0
    bit = 1 << ((code - 1) % 32)
    if stop3_mask & bit:
        return STOP_3
    if stop2_mask & bit:
        return STOP_2
    return STOP_0
