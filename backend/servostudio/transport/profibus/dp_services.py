"""DP-V0 services carried in FDL data units (IEC 61784-1 CP 3/1, EN 50170 vol. 2 part 3): their SAPs and payloads.

A master addresses a service by destination SAP and sends from SAP 62 (class-1 master); the slave answers from the
service's SAP to SAP 62. Data_Exchange uses no SAP at all. Each payload class reads (`decode`) and writes
(`encode`) the exact bytes; `DpServiceError` names what is wrong with a payload.
"""

from __future__ import annotations

from dataclasses import dataclass

MASTER_SAP = 62
SET_SLAVE_ADDRESS_SAP = 55
READ_INPUTS_SAP = 56
READ_OUTPUTS_SAP = 57
GLOBAL_CONTROL_SAP = 58
GET_CONFIG_SAP = 59
SLAVE_DIAG_SAP = 60
SET_PRM_SAP = 61
CHK_CFG_SAP = 62

NO_MASTER = 0xFF
"""Slave_Diag master address of a slave no master has parameterised."""
WATCHDOG_BASE = 0.01
"""Seconds per watchdog factor unit: the watchdog time is 10 ms × WD_Fact_1 × WD_Fact_2."""


class DpServiceError(ValueError):
    """A DP service payload is malformed; the message says how."""


# Set_Prm station status bits
STATUS_WATCHDOG = 0x08
STATUS_FREEZE = 0x10
STATUS_SYNC = 0x20
STATUS_UNLOCK = 0x40
STATUS_LOCK = 0x80


@dataclass(frozen=True)
class SetPrm:
    """Set_Prm (SAP 61): lock the slave to this master, watchdog, ident number check, group, user parameters."""

    station_status: int
    watchdog_factor_1: int
    watchdog_factor_2: int
    min_tsdr: int
    ident_number: int
    group_ident: int
    user_data: bytes = b""

    HEADER = 7

    @classmethod
    def decode(cls, data: bytes) -> SetPrm:
        if len(data) < cls.HEADER:
            raise DpServiceError(f"Set_Prm needs at least {cls.HEADER} bytes, got {len(data)}")
        ident = data[4] << 8 | data[5]
        return cls(data[0], data[1], data[2], data[3], ident, data[6], bytes(data[cls.HEADER :]))

    def encode(self) -> bytes:
        head = (self.station_status, self.watchdog_factor_1, self.watchdog_factor_2, self.min_tsdr)
        ident = (self.ident_number >> 8, self.ident_number & 0xFF)
        return bytes((*head, *ident, self.group_ident)) + self.user_data

    @property
    def watchdog(self) -> float | None:
        """Watchdog time in seconds when WD_On is set."""
        if not self.station_status & STATUS_WATCHDOG:
            return None
        return WATCHDOG_BASE * self.watchdog_factor_1 * self.watchdog_factor_2


# Slave_Diag station status 1
DIAG_NOT_EXISTENT = 0x01
DIAG_NOT_READY = 0x02
DIAG_CONFIG_FAULT = 0x04
DIAG_EXTENDED = 0x08
DIAG_NOT_SUPPORTED = 0x10
DIAG_INVALID_RESPONSE = 0x20
DIAG_PRM_FAULT = 0x40
DIAG_MASTER_LOCK = 0x80
# station status 2
DIAG_PRM_REQUEST = 0x01
DIAG_STATIC = 0x02
DIAG_ALWAYS_ONE = 0x04
DIAG_WATCHDOG_ON = 0x08
DIAG_FREEZE_MODE = 0x10
DIAG_SYNC_MODE = 0x20
DIAG_DEACTIVATED = 0x80


@dataclass(frozen=True)
class SlaveDiag:
    """Slave_Diag response (SAP 60 → 62): three status bytes, the master it is locked to, its ident number."""

    status_1: int
    status_2: int
    status_3: int
    master_address: int
    ident_number: int
    extended: bytes = b""

    LENGTH = 6

    @classmethod
    def decode(cls, data: bytes) -> SlaveDiag:
        if len(data) < cls.LENGTH:
            raise DpServiceError(f"Slave_Diag needs at least {cls.LENGTH} bytes, got {len(data)}")
        return cls(data[0], data[1], data[2], data[3], data[4] << 8 | data[5], bytes(data[cls.LENGTH :]))

    def encode(self) -> bytes:
        ident = (self.ident_number >> 8, self.ident_number & 0xFF)
        return bytes((self.status_1, self.status_2, self.status_3, self.master_address, *ident)) + self.extended

    @property
    def ready_for_data_exchange(self) -> bool:
        blocking = DIAG_NOT_EXISTENT | DIAG_NOT_READY | DIAG_CONFIG_FAULT | DIAG_PRM_FAULT
        return not self.status_1 & blocking and not self.status_2 & DIAG_PRM_REQUEST


# Global_Control command bits
CLEAR_DATA = 0x02
UNFREEZE = 0x04
FREEZE = 0x08
UNSYNC = 0x10
SYNC = 0x20


@dataclass(frozen=True)
class GlobalControl:
    """Global_Control (SAP 58, broadcast, no reply): SYNC/UNSYNC latch outputs, FREEZE/UNFREEZE inputs."""

    command: int
    group_select: int = 0

    LENGTH = 2

    @classmethod
    def decode(cls, data: bytes) -> GlobalControl:
        if len(data) != cls.LENGTH:
            raise DpServiceError(f"Global_Control has {cls.LENGTH} bytes, got {len(data)}")
        return cls(data[0], data[1])

    def encode(self) -> bytes:
        return bytes((self.command, self.group_select))

    def addresses(self, group_ident: int) -> bool:
        """Group_Select 0 addresses every slave, otherwise the slaves sharing a group bit."""
        return self.group_select == 0 or bool(self.group_select & group_ident)
