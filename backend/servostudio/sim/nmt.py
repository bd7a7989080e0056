"""NMT states and command specifiers (CiA 301 §7.3.2)."""

from __future__ import annotations

import enum

NMT_COB_ID = 0x000
HEARTBEAT_BASE = 0x700


class NmtState(enum.StrEnum):
    INITIALISING = "INITIALISING"
    PRE_OPERATIONAL = "PRE-OPERATIONAL"
    OPERATIONAL = "OPERATIONAL"
    STOPPED = "STOPPED"

    @property
    def heartbeat_code(self) -> int:
        """State byte of a heartbeat / node-guarding answer."""
        return _HEARTBEAT_CODES[self]


_HEARTBEAT_CODES = {
    NmtState.INITIALISING: 0x00,
    NmtState.STOPPED: 0x04,
    NmtState.OPERATIONAL: 0x05,
    NmtState.PRE_OPERATIONAL: 0x7F,
}


class NmtCommand(enum.IntEnum):
    START = 0x01
    STOP = 0x02
    ENTER_PRE_OPERATIONAL = 0x80
    RESET_NODE = 0x81
    RESET_COMMUNICATION = 0x82
