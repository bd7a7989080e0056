"""Errors and warnings of the simulated TTA-PRO as its PNUs show them (TTA-PRO Profibus Communication Profile,
Chapter 3, L1792-1868 and L2457-2485): the numeric drive error code (PZD signal 0x12F3, PNU 755), the 3-byte
positioner error code PNU 773, the power stage fault code PNU 778 and the warning code PNU 873.

The drive model raises numeric codes; this module knows which bits of 773 / 778 each code sets. The numeric list
is the key because it names every fault once; the bit fields are derived from it.
"""

from __future__ import annotations

BIT_773 = {
    1: 17,  # E2PPAR
    2: 18,  # E2PSEQ
    3: 20,  # SEQWR
    4: 16,  # HOME
    5: 19,  # E2PCOG
    6: 4,  # MEM
    10: 1,  # I²t
    11: 2,  # RDC / COUNT
    12: 3,  # POS
    13: 5,  # BUS
    14: 7,  # BUSY
    28: 10,  # RES / COD / HES
    32: 10,
    33: 13,  # TMOT
    40: 11,  # AP
}
POWER_BIT_773 = 9
POWER_CODES_778 = {20: 2, 21: 3, 22: 4, 23: 5, 24: 6, 25: 7}
"""Numeric code -> the code in PNU 778 bits 0-2."""
POWER_BITS_778 = {30: 3, 35: 9, 38: 11, 39: 15, 40: 4}
"""Numeric code -> a single bit of PNU 778."""
FOLLOWING_ERROR = 12
BUS_ERROR = 13
I2T = 10

WARNING_I2T = 1 << 1
"""PNU 873 bit 1; bits 11 (drive) and 13 (motor temperature) are not modelled."""


class FaultRegister:
    """The latched faults (cleared by the fault acknowledge, CW7) and the present warnings."""

    def __init__(self) -> None:
        self.active: list[int] = []
        self.warnings = 0

    @property
    def faulted(self) -> bool:
        return bool(self.active)

    def raise_fault(self, code: int) -> bool:
        """Latch `code`; True when it is new."""
        if code in self.active:
            return False
        self.active.append(code)
        return True

    def acknowledge(self) -> None:
        self.active.clear()

    def drive_error_code(self) -> int:
        """PNU 755 / signal 0x12F3: the first fault still latched, 0 for none."""
        return self.active[0] if self.active else 0

    def positioner_error_code(self) -> int:
        """PNU 773."""
        word = 0
        for code in self.active:
            if code in POWER_CODES_778 or code in POWER_BITS_778:
                word |= 1 << POWER_BIT_773
            if code in BIT_773:
                word |= 1 << BIT_773[code]
        return word

    def power_stage_code(self) -> int:
        """PNU 778."""
        word = 0
        for code in self.active:
            word |= POWER_CODES_778.get(code, 0)
            if code in POWER_BITS_778:
                word |= 1 << POWER_BITS_778[code]
        return word
