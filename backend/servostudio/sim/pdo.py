"""Process data objects: RPDO/TPDO configuration from the dictionary, packing, and transmission types.

Configuration is read from 0x1400+/0x1600+ (RPDO) and 0x1800+/0x1A00+ (TPDO) whenever one of them was written and
on every NMT state change, so the defaults of the EDS are the default mappings. Transmission types:
- TPDO 1–240: every n-th SYNC; 0: at SYNC when the mapped data changed; 253: only on a remote request;
  254: XtrapulsPac "TPDO_Count" mode when the device has 0x23A0 (sent at SYNC when 0x23A0 == 0x23A1,n), otherwise
  like 255; 255: once on entering OPERATIONAL, then when the first mapped object changes (checked every control
  period), and every event time (sub 5) when set. The inhibit time (sub 3, 100 µs units) is honoured when the
  dictionary has it.
- RPDO 0–240: the data is applied at the next SYNC; 254/255: applied on reception.
Any valid TPDO answers a remote frame on its COB-ID. An RPDO shorter than its mapping raises EMCY 0x8210.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from servostudio.od.datatypes import decode, encode
from servostudio.od.model import Value, Variable
from servostudio.sim import sdo_abort
from servostudio.sim.clock import VirtualClock
from servostudio.sim.frame import Frame
from servostudio.sim.objects import ObjectStore
from servostudio.sim.sdo_abort import SdoAbort

RPDO_COMMUNICATION, RPDO_MAPPING = 0x1400, 0x1600
TPDO_COMMUNICATION, TPDO_MAPPING = 0x1800, 0x1A00
PDO_COUNT_LIMIT = 512
TPDO_COUNT = 0x23A0
TPDO_CONTROL = 0x23A1
DUMMY_OBJECTS = range(0x0002, 0x0008)
PDO_LENGTH_ERROR = 0x8210
_NEVER_SENT = object()
COB_ID_INVALID = 0x80000000
COB_ID_NO_RTR = 0x40000000


@dataclass
class MappedEntry:
    variable: Variable | None  # None for a dummy entry (RPDO only)
    bits: int


@dataclass
class Pdo:
    number: int  # 0-based
    cob_id: int
    transmission_type: int
    entries: list[MappedEntry]
    rtr_allowed: bool = True
    inhibit_time: float = 0.0
    event_time: float = 0.0
    sync_counter: int = 0
    last_payload: bytes | None = None
    last_first_value: object = None
    next_allowed: float = 0.0
    next_event: float = 0.0
    pending: bytes | None = field(default=None)

    @property
    def length(self) -> int:
        return (sum(entry.bits for entry in self.entries) + 7) // 8


class PdoEngine:
    def __init__(
        self,
        store: ObjectStore,
        clock: VirtualClock,
        transmit: Callable[[Frame], None],
        emergency: Callable[[int], None],
    ) -> None:
        self.store = store
        self.clock = clock
        self._transmit = transmit
        self._emergency = emergency
        self.rpdos: list[Pdo] = []
        self.tpdos: list[Pdo] = []
        self._event_tpdos: list[Pdo] = []
        self.active = False
        self._dirty = True
        self._register_hooks()

    # -- configuration --------------------------------------------------------------------------------------------

    def _register_hooks(self) -> None:
        od = self.store.od
        for number in range(PDO_COUNT_LIMIT):
            for base in (RPDO_COMMUNICATION, TPDO_COMMUNICATION):
                if base + number in od:
                    self.store.on_write(base + number, None, self._mark_dirty)
            if RPDO_MAPPING + number in od:
                self.store.on_write(RPDO_MAPPING + number, None, self._check_rpdo_mapping)
            if TPDO_MAPPING + number in od:
                self.store.on_write(TPDO_MAPPING + number, None, self._check_tpdo_mapping)

    def _mark_dirty(self, index: int, sub: int, value: object) -> None:
        self._dirty = True

    def _check_rpdo_mapping(self, index: int, sub: int, value: Value) -> None:
        self._check_mapping(index, sub, int(value), receive=True)

    def _check_tpdo_mapping(self, index: int, sub: int, value: Value) -> None:
        self._check_mapping(index, sub, int(value), receive=False)

    def _check_mapping(self, index: int, sub: int, value: int, receive: bool) -> None:
        """Refuse what cannot be mapped (0x06040041) or would not fit 8 bytes (0x06040042)."""
        self._dirty = True
        if sub == 0:
            if any((index, entry) not in self.store for entry in range(1, value + 1)):
                raise SdoAbort(sdo_abort.VALUE_TOO_HIGH, f"0x{index:04X} has fewer than {value} entries")
            total = sum(int(self.store.get(index, entry)) & 0xFF for entry in range(1, value + 1))
            if total > 64:
                raise SdoAbort(sdo_abort.PDO_LENGTH_EXCEEDED, f"0x{index:04X}: {total} bits mapped")
            return
        if value == 0:
            return
        self._resolve_entry(value, receive)

    def _resolve_entry(self, entry: int, receive: bool) -> MappedEntry:
        index, sub, bits = entry >> 16, (entry >> 8) & 0xFF, entry & 0xFF
        if receive and index in DUMMY_OBJECTS:
            return MappedEntry(None, bits)
        var = self.store.od.get(index, sub)
        if var is None or not var.pdo_mappable or bits == 0 or var.data_type.bits is None or bits > var.data_type.bits:
            raise SdoAbort(sdo_abort.CANNOT_BE_MAPPED, f"0x{entry:08X} cannot be mapped")
        if (receive and not var.access.writable) or (not receive and not var.access.readable):
            raise SdoAbort(sdo_abort.CANNOT_BE_MAPPED, f"0x{entry:08X} has the wrong access for this PDO")
        return MappedEntry(var, bits)

    def configure(self) -> None:
        """Rebuild the PDO tables from the communication and mapping objects."""
        self.rpdos = self._read_pdos(RPDO_COMMUNICATION, RPDO_MAPPING, receive=True)
        self.tpdos = self._read_pdos(TPDO_COMMUNICATION, TPDO_MAPPING, receive=False)
        counting = (TPDO_COUNT, 0) in self.store  # type 254 is TPDO_Count mode, not event-driven
        self._event_tpdos = [
            pdo for pdo in self.tpdos if pdo.transmission_type == 255 or (pdo.transmission_type == 254 and not counting)
        ]
        self._dirty = False

    def _read_pdos(self, communication: int, mapping: int, receive: bool) -> list[Pdo]:
        store, pdos = self.store, []
        for number in range(PDO_COUNT_LIMIT):
            if (communication + number, 1) not in store:
                continue
            cob_id = int(store.get(communication + number, 1))
            if cob_id & COB_ID_INVALID:
                continue
            entries = []
            if (mapping + number, 0) in store:
                for sub in range(1, int(store.get(mapping + number, 0)) + 1):
                    try:
                        entries.append(self._resolve_entry(int(store.get(mapping + number, sub)), receive))
                    except (SdoAbort, KeyError):
                        entries = []
                        break
            pdo = Pdo(number, cob_id & 0x7FF, self._sub(communication + number, 2, 255), entries)
            pdo.rtr_allowed = not cob_id & COB_ID_NO_RTR
            pdo.inhibit_time = self._sub(communication + number, 3, 0) * 100e-6
            pdo.event_time = self._sub(communication + number, 5, 0) * 1e-3
            pdos.append(pdo)
        return pdos

    def _sub(self, index: int, sub: int, default: int) -> int:
        return int(self.store.get(index, sub)) if (index, sub) in self.store else default

    # -- state ----------------------------------------------------------------------------------------------------

    def set_active(self, active: bool) -> None:
        """PDOs run only in OPERATIONAL; entering it (re)reads the configuration."""
        self.active = active
        if active:
            self.configure()
            for pdo in self.tpdos:  # event-driven TPDOs go out once on entering OPERATIONAL (initial values)
                pdo.last_payload = None
                pdo.last_first_value = _NEVER_SENT
                pdo.next_event = self.clock.now + pdo.event_time

    # -- reception ------------------------------------------------------------------------------------------------

    def receive(self, frame: Frame) -> bool:
        """Handle an RPDO or a remote request for a TPDO; False when the frame is not a PDO of this node."""
        if not self.active:
            return False
        if self._dirty:
            self.configure()
        if frame.rtr:
            for pdo in self.tpdos:
                if pdo.cob_id == frame.can_id and pdo.rtr_allowed:
                    self._send(pdo)
                    return True
            return False
        for pdo in self.rpdos:
            if pdo.cob_id == frame.can_id:
                self._receive_rpdo(pdo, frame.data)
                return True
        return False

    def _receive_rpdo(self, pdo: Pdo, data: bytes) -> None:
        if len(data) < pdo.length:
            self._emergency(PDO_LENGTH_ERROR)
            return
        if pdo.transmission_type <= 240:
            pdo.pending = bytes(data)
        else:
            self._apply(pdo, bytes(data))

    def _apply(self, pdo: Pdo, data: bytes) -> None:
        payload = int.from_bytes(data, "little")
        offset = 0
        for entry in pdo.entries:
            raw = (payload >> offset) & ((1 << entry.bits) - 1)
            offset += entry.bits
            if entry.variable is None:
                continue
            try:
                self.store.write_value(entry.variable, _unpack(entry.variable, raw, entry.bits))
            except SdoAbort:
                continue  # a refused value is dropped, the other mapped objects still apply

    # -- transmission ---------------------------------------------------------------------------------------------

    def on_sync(self) -> None:
        if not self.active:
            return
        if self._dirty:
            self.configure()
        for pdo in self.rpdos:
            if pdo.pending is not None:
                data, pdo.pending = pdo.pending, None
                self._apply(pdo, data)
        counter = int(self.store.get(TPDO_COUNT, 0)) if (TPDO_COUNT, 0) in self.store else None
        for pdo in self.tpdos:
            kind = pdo.transmission_type
            if 1 <= kind <= 240:
                pdo.sync_counter += 1
                if pdo.sync_counter >= kind:
                    pdo.sync_counter = 0
                    self._send(pdo)
            elif kind == 0:
                payload = self._payload(pdo)
                if payload != pdo.last_payload:
                    self._send(pdo, payload)
            elif kind == 254 and counter is not None and self._count_reached(pdo, counter):
                self._send(pdo)

    def _count_reached(self, pdo: Pdo, counter: int) -> bool:
        """TPDO_Count mode: the counter 0x23A0 equals this TPDO's entry of 0x23A1."""
        control = (TPDO_CONTROL, pdo.number + 1)
        return control in self.store and counter == self.store.get(*control)

    def poll(self) -> None:
        """Once per control period: event-driven TPDOs (first mapped object changed, or event timer)."""
        if not self.active:
            return
        if self._dirty:
            self.configure()
        now = self.clock.now
        for pdo in self._event_tpdos:
            value = self._first_value(pdo)
            timer_due = pdo.event_time > 0 and now >= pdo.next_event
            if (value != pdo.last_first_value or timer_due) and now >= pdo.next_allowed:
                pdo.last_first_value = value
                self._send(pdo)

    def _first_value(self, pdo: Pdo) -> object:
        if not pdo.entries or pdo.entries[0].variable is None:
            return None
        return self.store.get(*pdo.entries[0].variable.key)

    def _payload(self, pdo: Pdo) -> bytes:
        payload, offset = 0, 0
        for entry in pdo.entries:
            var = entry.variable
            if var is not None:  # always so: only an RPDO has dummy entries
                payload |= _pack(var, self.store.read_value(var), entry.bits) << offset
            offset += entry.bits
        return payload.to_bytes(pdo.length, "little")

    def _send(self, pdo: Pdo, payload: bytes | None = None) -> None:
        payload = self._payload(pdo) if payload is None else payload
        pdo.last_payload = payload
        pdo.next_allowed = self.clock.now + pdo.inhibit_time
        pdo.next_event = self.clock.now + pdo.event_time
        self._transmit(Frame(pdo.cob_id, payload))


def _pack(var: Variable, value: Value, bits: int) -> int:
    raw = int.from_bytes(encode(var.data_type, value), "little")
    return raw & ((1 << bits) - 1)


def _unpack(var: Variable, raw: int, bits: int) -> Value:
    data_type = var.data_type
    if data_type.is_integer:
        if data_type.is_signed and raw >> (bits - 1) & 1:
            raw -= 1 << bits  # two's complement, also for a shortened mapping (0x60C10110: 32-bit data as 16 bits)
        return raw
    return decode(data_type, raw.to_bytes(data_type.fixed_size, "little"))
