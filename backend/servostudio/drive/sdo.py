"""SDO client engine: expedited and segmented transfers, one at a time per node, all nodes in parallel.

Every transfer is a small state machine driven by the frames the bus link delivers; nothing blocks while a drive
thinks.  A caller gets a ``concurrent.futures.Future`` (``asyncio.wrap_future`` makes it awaitable), so a thread can
wait on it and the event loop never does.  Each node has a FIFO: the next request to a node leaves the moment the
previous response arrives, from the reader thread itself, so a backup of many drives keeps every drive busy and
the bus full without one thread per drive.

A read whose request got no answer at all is sent once more before it times out (reads have no side effect, and
one lost frame should not fail a 400-object backup); writes are never repeated.

Block transfers are not used: the dictionaries' values fit in one expedited frame or a few segments, where a
block transfer needs more frames than a segmented one.
"""

from __future__ import annotations

import struct
import threading
import time
from collections import deque
from concurrent.futures import Future
from collections.abc import Callable
from dataclasses import dataclass, field

from servostudio.drive.abort_codes import abort_text
from servostudio.drive.link import BusLink, LinkDownError

SDO_REQUEST = 0x600
SDO_RESPONSE = 0x580
DEFAULT_TIMEOUT = 0.5
UPLOAD_RETRIES = 1  # a read has no side effect: one lost frame should not fail a 400-object backup
ABORT_TIMEOUT = 0x05040000
ABORT_COMMAND = 0x05040001
ABORT_TOGGLE = 0x05030000


class SdoError(Exception):
    """An SDO transfer failed; the message names the node and the object."""

    def __init__(self, node: int, index: int, sub: int, reason: str) -> None:
        super().__init__(f"node {node}, object 0x{index:04X},{sub}: {reason}")
        self.node = node
        self.index = index
        self.sub = sub
        self.reason = reason


class SdoAbortError(SdoError):
    """The drive refused the transfer with a CiA 301 abort code."""

    def __init__(self, node: int, index: int, sub: int, code: int) -> None:
        super().__init__(node, index, sub, f"{abort_text(code)} (SDO abort 0x{code:08X})")
        self.code = code


class SdoTimeoutError(SdoError):
    """The drive did not answer in time (absent, unpowered, or the link is broken)."""


class SdoLinkError(SdoError):
    """The bus went down before or during the transfer."""


@dataclass
class _Transfer:
    node: int
    index: int
    sub: int
    timeout: float
    download: bytes | None = None  # None: upload
    future: Future = field(default_factory=Future)
    deadline: float = 0.0
    received: bytearray = field(default_factory=bytearray)
    expected_size: int | None = None
    toggle: int = 0
    offset: int = 0
    segmented: bool = False
    abort_on_timeout: bool = True
    retries: int = 0  # times the initiate request is sent again when it got no answer at all
    answered: bool = False
    repeated: bool = False
    convert: Callable[[object], object] | None = None  # applied to the result before the future gets it

    def multiplexer(self) -> bytes:
        return struct.pack("<HB", self.index, self.sub)


def _stale(transfer: _Transfer, data: bytes) -> bool:
    """An answer that belongs to an earlier request: a late reply about another object (after a timeout), or a
    second reply to a repeated initiate request while the segments are already running."""
    command = data[0]
    initiate_reply = command >> 5 in (2, 3)
    if (initiate_reply or command == 0x80) and data[1:4] != transfer.multiplexer():
        return True
    in_segments = transfer.offset > 0 if transfer.download is not None else transfer.segmented
    return initiate_reply and in_segments


class SdoEngine:
    """All SDO client transfers of one bus."""

    def __init__(self, link: BusLink, timeout: float = DEFAULT_TIMEOUT) -> None:
        self.link = link
        self.timeout = timeout
        self._lock = threading.RLock()  # futures' callbacks may submit the next transfer
        self._queues: dict[int, deque[_Transfer]] = {}
        self._active: dict[int, _Transfer] = {}
        self._finished: deque[tuple[_Transfer, object]] = deque()  # outcomes to hand over once the lock is free
        link.add_ticker(self._check_timeouts)
        link.on_state(self._link_state)

    # -- public API --------------------------------------------------------------------------------------------
    def upload(self, node: int, index: int, sub: int, timeout: float | None = None, probe: bool = False,
               convert: Callable[[bytes], object] | None = None) -> Future:
        """Read an object; the future gives its bytes, or ``convert(bytes)`` (a ValueError fails the future).

        A ``probe`` (scan) sends no abort when the node stays silent: there is nobody to tell, and on a slow serial
        link 127 useless abort frames would cost most of a second.
        """
        return self._submit(_Transfer(node, index, sub, timeout or self.timeout, abort_on_timeout=not probe,
                                      convert=convert, retries=0 if probe else UPLOAD_RETRIES))

    def download(self, node: int, index: int, sub: int, data: bytes, timeout: float | None = None,
                 convert: Callable[[None], object] | None = None) -> Future:
        """Write an object; the future gives None (or ``convert(None)``) once the drive confirmed."""
        if not data:
            raise ValueError("an SDO download needs at least one byte")
        return self._submit(_Transfer(node, index, sub, timeout or self.timeout, download=bytes(data),
                                      convert=convert))

    # -- internals ---------------------------------------------------------------------------------------------
    def _submit(self, transfer: _Transfer) -> Future:
        if not 1 <= transfer.node <= 127:
            raise ValueError(f"node ID {transfer.node} outside 1..127")
        with self._lock:
            if transfer.node not in self._queues:
                self._queues[transfer.node] = deque()
                self.link.subscribe(SDO_RESPONSE + transfer.node, self._on_response)
            self._queues[transfer.node].append(transfer)
            start = transfer.node not in self._active
            if start:
                self._start_next(transfer.node)
        self._hand_over()
        return transfer.future

    def _start_next(self, node: int) -> None:
        """Start the next queued transfer of ``node`` (lock held); failures to send complete it at once."""
        queue = self._queues[node]
        while queue:
            transfer = queue.popleft()
            if not transfer.future.set_running_or_notify_cancel():  # from now on cancel() refuses: the
                continue                                            # transfer's outcome is always known
            self._active[node] = transfer
            if self._send(transfer, self._initiate(transfer)):
                return
        self._active.pop(node, None)

    def _initiate(self, transfer: _Transfer) -> bytes:
        data = transfer.download
        if data is None:
            return bytes([0x40]) + transfer.multiplexer() + bytes(4)
        if len(data) <= 4:
            command = 0x23 | ((4 - len(data)) << 2)
            return bytes([command]) + transfer.multiplexer() + data.ljust(4, b"\0")
        transfer.segmented = True
        return bytes([0x21]) + transfer.multiplexer() + struct.pack("<I", len(data))

    def _send(self, transfer: _Transfer, frame: bytes) -> bool:
        """Send one request of the active transfer; on a dead link fail it (lock held) and report False."""
        transfer.deadline = time.monotonic() + transfer.timeout
        try:
            self.link.send(SDO_REQUEST + transfer.node, frame)
        except LinkDownError as error:
            self._finish(transfer, SdoLinkError(transfer.node, transfer.index, transfer.sub, str(error)))
            return False
        return True

    def _on_response(self, cob_id: int, data: bytes, timestamp: float) -> None:
        node = cob_id - SDO_RESPONSE
        with self._lock:
            transfer = self._active.get(node)
            if transfer is None or len(data) < 8 or _stale(transfer, data):
                return
            transfer.answered = True
            try:
                follow_up = self._advance(transfer, data)
            except SdoError as error:
                self._finish(transfer, error)
                follow_up = None
            if follow_up is None:
                self._start_next(node)
            elif not self._send(transfer, follow_up):
                self._start_next(node)
        self._hand_over()

    def _advance(self, transfer: _Transfer, data: bytes) -> bytes | None:
        """Process one response; return the next request, or None when the transfer is finished."""
        command = data[0]
        if command == 0x80:
            code = struct.unpack_from("<I", data, 4)[0]
            raise SdoAbortError(transfer.node, transfer.index, transfer.sub, code)
        if transfer.download is None:
            return self._advance_upload(transfer, command, data)
        return self._advance_download(transfer, command, data)

    def _advance_upload(self, transfer: _Transfer, command: int, data: bytes) -> bytes | None:
        if not transfer.segmented:
            self._expect(transfer, command >> 5 == 2 and data[1:4] == transfer.multiplexer(), data)
            if command & 0x02:  # expedited
                size = 4 - ((command >> 2) & 0x3) if command & 0x01 else 4
                self._finish(transfer, bytes(data[4 : 4 + size]))
                return None
            transfer.segmented = True
            transfer.expected_size = struct.unpack_from("<I", data, 4)[0] if command & 0x01 else None
            return bytes([0x60]) + bytes(7)
        self._expect(transfer, command >> 5 == 0, data)
        if (command >> 4) & 1 != transfer.toggle:
            self._abort(transfer, ABORT_TOGGLE)
            raise SdoError(transfer.node, transfer.index, transfer.sub, "segment toggle bit not alternated")
        transfer.received += data[1 : 8 - ((command >> 1) & 0x7)]
        if command & 0x01:  # last segment
            size = transfer.expected_size
            self._finish(transfer, bytes(transfer.received[:size] if size is not None else transfer.received))
            return None
        transfer.toggle ^= 1
        return bytes([0x60 | transfer.toggle << 4]) + bytes(7)

    def _advance_download(self, transfer: _Transfer, command: int, data: bytes) -> bytes | None:
        payload = transfer.download
        assert payload is not None
        if transfer.offset == 0 and command >> 5 == 3:
            self._expect(transfer, data[1:4] == transfer.multiplexer(), data)
            if not transfer.segmented:
                self._finish(transfer, None)
                return None
        else:
            self._expect(transfer, command >> 5 == 1 and (command >> 4) & 1 == transfer.toggle ^ 1, data)
            if transfer.offset >= len(payload):
                self._finish(transfer, None)
                return None
        chunk = payload[transfer.offset : transfer.offset + 7]
        transfer.offset += len(chunk)
        last = transfer.offset >= len(payload)
        segment_command = transfer.toggle << 4 | (7 - len(chunk)) << 1 | int(last)
        transfer.toggle ^= 1
        return bytes([segment_command]) + chunk.ljust(7, b"\0")

    def _expect(self, transfer: _Transfer, condition: bool, data: bytes) -> None:
        if not condition:
            self._abort(transfer, ABORT_COMMAND)
            raise SdoError(transfer.node, transfer.index, transfer.sub,
                           f"unexpected SDO response {data.hex(' ')}")

    def _abort(self, transfer: _Transfer, code: int) -> None:
        try:
            frame = bytes([0x80]) + transfer.multiplexer() + struct.pack("<I", code)
            self.link.send(SDO_REQUEST + transfer.node, frame)
        except LinkDownError:
            pass

    def _finish(self, transfer: _Transfer, outcome: object) -> None:
        """End the active transfer of its node (lock held); its future completes in `_hand_over`, after the node's
        next request has left and the lock is released (conversion and the caller's callbacks then delay neither)."""
        if self._active.get(transfer.node) is transfer:
            del self._active[transfer.node]
        self._finished.append((transfer, outcome))

    def _hand_over(self) -> None:
        """Complete the futures of finished transfers (lock not held)."""
        while self._finished:
            try:
                transfer, outcome = self._finished.popleft()
            except IndexError:  # another thread took the last one
                return
            self._complete(transfer, outcome)

    @staticmethod
    def _complete(transfer: _Transfer, outcome: object) -> None:
        if transfer.future.done():
            return
        if not isinstance(outcome, Exception) and transfer.convert is not None:
            try:
                outcome = transfer.convert(outcome)
            except ValueError as error:
                outcome = error
        if isinstance(outcome, Exception):
            transfer.future.set_exception(outcome)
        else:
            transfer.future.set_result(outcome)

    def _check_timeouts(self, now: float) -> None:
        with self._lock:
            expired = [transfer for transfer in self._active.values() if now > transfer.deadline]
            for transfer in expired:
                if transfer.retries > 0 and not transfer.answered:
                    transfer.retries -= 1
                    transfer.repeated = True
                    if not self._send(transfer, self._initiate(transfer)):
                        self._start_next(transfer.node)
                    continue
                if transfer.abort_on_timeout:
                    self._abort(transfer, ABORT_TIMEOUT)
                sent = " (request sent twice)" if transfer.repeated else ""
                self._finish(transfer, SdoTimeoutError(
                    transfer.node, transfer.index, transfer.sub,
                    f"no SDO response within {transfer.timeout * 1000:.0f} ms on bus {self.link.name}{sent}"))
                self._start_next(transfer.node)
        self._hand_over()

    def _link_state(self, connected: bool, reason: str) -> None:
        if connected:
            return
        with self._lock:
            pending = list(self._active.values())
            for queue in self._queues.values():
                pending += queue
                queue.clear()
            self._active.clear()
            for transfer in pending:
                if not transfer.future.done():
                    transfer.future.set_exception(SdoLinkError(
                        transfer.node, transfer.index, transfer.sub, f"bus {self.link.name} lost: {reason}"))
