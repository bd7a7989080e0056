"""Bus monitor: EMCY, boot-up and heartbeat frames → events (decoded faults, NMT state changes, heartbeat loss).

CiA 402 state changes: when a scan found a TPDO carrying the status word first (``watch_statusword``), every such
PDO is decoded and a change of state is reported — passively, without polling the drive.  Status words read by
other means (state control, the services' slow status word watch) come in through ``report_statusword``; whatever
the source, one ``drive_state`` event per change of state.

Heartbeat loss: once a node has sent two heartbeats, its period is known; silence for more than
``LOSS_FACTOR`` periods (at least ``MIN_LOSS_TIME``) is reported once, and the next heartbeat reports it back.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable

from servostudio.drive.cia402 import decode_state
from servostudio.drive.faults import Emergency, FaultInfo, faults_from_words, unpack_emergency
from servostudio.drive.link import BusLink
from servostudio.drive.nmt import NMT_STATES
from servostudio.drive.profiles import DeviceProfile
from servostudio.drive.profiles.base import EmcyLayout

EventSink = Callable[[dict[str, object]], None]
LOSS_FACTOR = 2.5
MIN_LOSS_TIME = 0.3


def decode_emergency(node: int, data: bytes, profile: DeviceProfile | None) -> Emergency:
    code, register, manufacturer = unpack_emergency(data)
    faults: list[FaultInfo] = []
    if profile is not None and code:
        if profile.emcy_layout is EmcyLayout.CODE_BYTE and manufacturer[0] in profile.errors:
            faults = [profile.errors[manufacturer[0]]]
        elif profile.emcy_layout is EmcyLayout.BITFIELD:
            word = int.from_bytes(manufacturer[:4], "little")
            faults = faults_from_words(profile.errors, [(word, 1)], profile.coded_error_bits)
        else:
            faults = [fault for fault in [profile.code_fault(code)] if fault]
    return Emergency(node, code, register, manufacturer, tuple(faults))


class DriveStateReporter:
    """One ``drive_state`` event per change of a node's CiA 402 state, from status words however they were read.
    A bus without CAN frames (a PROFIBUS-DP line) has only this part, fed by its own adapter: no NMT states."""

    def __init__(self, bus: str, sink: EventSink) -> None:
        self.bus = bus
        self._sink = sink
        self._lock = threading.Lock()
        self._drive_state: dict[int, str | None] = {}

    def nmt_state(self, node: int) -> str | None:
        """None: no heartbeat or boot-up seen (on a bus without NMT, never)."""
        return None

    def report_statusword(self, node: int, statusword: int) -> None:
        """A status word read by other means (state control): reported if the state changed."""
        state = decode_state(statusword)
        name = state.value if state else None
        with self._lock:  # reader thread and request threads report concurrently: one event per change
            changed = self._drive_state.get(node, "unknown") != name
            self._drive_state[node] = name
        if changed:
            self._emit({"type": "drive_state", "node": node, "state": name, "statusword": statusword})

    def _emit(self, event: dict[str, object]) -> None:
        self._sink({"bus": self.bus, "time": time.time(), **event})


class BusMonitor(DriveStateReporter):
    """Watches the error-control and EMCY frames of one bus and reports what happens as event dicts."""

    def __init__(self, link: BusLink, sink: EventSink, profile_of: Callable[[int], DeviceProfile | None]) -> None:
        super().__init__(link.name, sink)
        self.link = link
        self._profile_of = profile_of
        self._last_seen: dict[int, float] = {}
        self._period: dict[int, float] = {}
        self._nmt_state: dict[int, str] = {}
        self._lost: set[int] = set()
        self._statusword_cob: dict[int, int] = {}
        for node in range(1, 128):
            link.subscribe(0x080 + node, self._on_emergency)
            link.subscribe(0x700 + node, self._on_error_control)
        link.add_ticker(self._check_heartbeats)

    def nmt_state(self, node: int) -> str | None:
        return self._nmt_state.get(node)

    def watch_statusword(self, node: int, cob_id: int) -> None:
        """Decode the status word from the TPDO ``cob_id`` of ``node`` (mapped as its first object)."""
        previous = self._statusword_cob.get(node)
        if previous == cob_id:
            return
        if previous is not None:
            self.link.unsubscribe(previous, self._on_statusword_pdo)
        self._statusword_cob[node] = cob_id
        self.link.subscribe(cob_id, self._on_statusword_pdo)

    def _on_statusword_pdo(self, cob_id: int, data: bytes, timestamp: float) -> None:
        for node, watched in self._statusword_cob.items():
            if watched == cob_id and len(data) >= 2:
                self.report_statusword(node, int.from_bytes(data[:2], "little"))

    def _on_emergency(self, cob_id: int, data: bytes, timestamp: float) -> None:
        node = cob_id - 0x080
        emergency = decode_emergency(node, data, self._profile_of(node))
        self._emit({"type": "emcy", **emergency.as_dict()})

    def _on_error_control(self, cob_id: int, data: bytes, timestamp: float) -> None:
        if not data:
            return
        node = cob_id - 0x700
        state = NMT_STATES.get(data[0] & 0x7F, f"unknown 0x{data[0]:02X}")
        now = time.monotonic()
        with self._lock:
            previous_time = self._last_seen.get(node)
            self._last_seen[node] = now
            if previous_time is not None and state != "INITIALISING":
                self._period[node] = now - previous_time
            back = node in self._lost
            self._lost.discard(node)
            changed = self._nmt_state.get(node) != state
            self._nmt_state[node] = state
        if state == "INITIALISING":
            self._period.pop(node, None)
            self._emit({"type": "bootup", "node": node})
        if back:
            self._emit({"type": "heartbeat_back", "node": node, "nmt_state": state})
        if changed:
            self._emit({"type": "nmt_state", "node": node, "nmt_state": state})

    def _check_heartbeats(self, now: float) -> None:
        lost = []
        with self._lock:
            for node, period in self._period.items():
                if node in self._lost:
                    continue
                if now - self._last_seen[node] > max(LOSS_FACTOR * period, MIN_LOSS_TIME):
                    self._lost.add(node)
                    lost.append((node, period))
        for node, period in lost:
            self._emit({"type": "heartbeat_lost", "node": node, "period_ms": round(period * 1000)})
