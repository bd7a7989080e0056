"""What the drive behaviour tells the CANopen stack: emergencies, and what it may read back from the stack.

The EMCY frame layout is the one of decisions.md §5: bytes 0–1 the CiA 402 error code (little-endian), byte 2 the
error register 0x1001, byte 3 the Infranor error code (1–64), bytes 4–7 manufacturer-specific. The stack keeps
0x1001 itself: bit 0 (generic) for every active error plus the class bit of the code's high byte; fault reset
clears it. With 0x205F (EMCY behaviour) 0 nothing is sent, 1 EMCY on error, 2 also the 0x0000 EMCY on reset; a
device without 0x205F behaves as 2 (CiA 301).
"""

from __future__ import annotations

import struct
from collections.abc import Callable

from servostudio.sim.frame import Frame
from servostudio.sim.objects import ObjectStore
from servostudio.sim.sequences import SequenceMemory

ERROR_REGISTER = 0x1001
PREDEFINED_ERROR_FIELD = 0x1003
EMCY_COB_ID = 0x1014
EMCY_BEHAVIOUR = 0x205F

_CLASS_BITS = {0x2: 0x02, 0x3: 0x04, 0x4: 0x08, 0x81: 0x10, 0x82: 0x10, 0xFF: 0x80}


def error_register_bits(error_code: int) -> int:
    """0x1001 bits for a CiA 301 error code: generic bit 0 plus current/voltage/temperature/communication/manuf."""
    bits = 0x01
    bits |= _CLASS_BITS.get(error_code >> 12, 0)
    bits |= _CLASS_BITS.get(error_code >> 8, 0)
    return bits


class DriveEvents:
    """The stack's side of the contract with `DriveBehaviour` (see docs/simulator.md)."""

    def __init__(
        self,
        store: ObjectStore,
        transmit: Callable[[Frame], None],
        nmt_state: Callable[[], str],
        emcy_allowed: Callable[[], bool],
    ) -> None:
        self._store = store
        self._transmit = transmit
        self._nmt_state = nmt_state
        self._emcy_allowed = emcy_allowed
        self.flash_busy = False
        """True while the node writes or reads its flash files: the behaviour shows it as status word bit 15."""
        self.emergencies_sent = 0
        self.sequences: SequenceMemory | None = None
        """The node's `SequenceMemory` (XtrapulsPac sequence mode) or None: the drive model reads sequences here."""

    @property
    def nmt_state(self) -> str:
        return self._nmt_state()

    def emergency(self, error_code: int, infranor_code: int = 0, manufacturer: bytes = b"") -> None:
        store = self._store
        register = error_register_bits(error_code)
        if (ERROR_REGISTER, 0) in store:
            register |= int(store.get(ERROR_REGISTER, 0))
            store.set(ERROR_REGISTER, 0, register)
        self._record_history(error_code, manufacturer)
        self._send(error_code, register, infranor_code, manufacturer, on_reset=False)

    def emergency_cleared(self) -> None:
        if (ERROR_REGISTER, 0) in self._store:
            self._store.set(ERROR_REGISTER, 0, 0)
        self._send(0x0000, 0, 0, b"", on_reset=True)

    def _send(self, error_code: int, register: int, infranor_code: int, manufacturer: bytes, on_reset: bool) -> None:
        store = self._store
        behaviour = int(store.get(EMCY_BEHAVIOUR, 0)) if (EMCY_BEHAVIOUR, 0) in store else 2
        if behaviour == 0 or (on_reset and behaviour < 2) or not self._emcy_allowed():
            return
        cob_id = int(store.get(EMCY_COB_ID, 0)) if (EMCY_COB_ID, 0) in store else 0x80 + store.node_id
        if cob_id & 0x80000000:
            return
        payload = struct.pack("<HBB", error_code, register, infranor_code) + bytes(manufacturer[:4]).ljust(4, b"\0")
        self._transmit(Frame(cob_id & 0x7FF, payload))
        self.emergencies_sent += 1

    def _record_history(self, error_code: int, manufacturer: bytes) -> None:
        """Push the error onto 0x1003 (newest in sub 1) when the dictionary has the pre-defined error field."""
        store = self._store
        if (PREDEFINED_ERROR_FIELD, 1) not in store:
            return
        depth = max(store.od.object(PREDEFINED_ERROR_FIELD).subs)
        entry = error_code | (int.from_bytes(bytes(manufacturer[:2]).ljust(2, b"\0"), "little") << 16)
        for sub in range(depth, 1, -1):
            store.set(PREDEFINED_ERROR_FIELD, sub, store.get(PREDEFINED_ERROR_FIELD, sub - 1))
        store.set(PREDEFINED_ERROR_FIELD, 1, entry)
        count = int(store.get(PREDEFINED_ERROR_FIELD, 0))
        store.set(PREDEFINED_ERROR_FIELD, 0, min(count + 1, depth))
