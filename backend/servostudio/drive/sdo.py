"""SDO client engine: expedited and segmented transfers, one at a time per node, all nodes in parallel.

Every transfer is a small state machine driven by the frames the bus link delivers; nothing blocks while a drive
thinks.  A caller gets a ``concurrent.futures.Future`` (``asyncio.wrap_future`` makes it awaitable), so a thread can
wait on it and the event loop never does.  Each node has a FIFO: the next request to a node leaves the moment the
previous response arrives, from the reader thread itself, so a backup of many drives keeps every drive busy and
the bus full without one thread per drive.  Futures complete after the reader's batch of frames was handled and
the follow-up requests left (``BusLink.after_dispatch``).

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
from collections.abc import Callable, Sequence
from concurrent.futures import CancelledError, Future

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


class _FutureCompletion:
    """The outcome of one transfer goes to a future (after ``convert`` of a successful result)."""

    __slots__ = ("convert", "future")

    def __init__(self, convert: Callable[[object], object] | None) -> None:
        self.future: Future = Future()
        self.convert = convert

    def start(self, slot: int) -> bool:
        return self.future.set_running_or_notify_cancel()  # from now on cancel() refuses: the outcome is known

    def drive_silent(self) -> None:
        """Nothing more to drop: the transfer itself ends with its timeout."""

    def done(self, slot: int, outcome: object) -> None:
        if self.future.done():
            return
        if not isinstance(outcome, Exception) and self.convert is not None:
            try:
                outcome = self.convert(outcome)
            except Exception as error:  # ValueError: bytes that are no value; anything else reaches the caller too
                outcome = error
        if isinstance(outcome, Exception):
            self.future.set_exception(outcome)
        else:
            self.future.set_result(outcome)


class TransferBatch:
    """Reads (or writes) of many objects of one node with one future for all: ``future`` gives a list, in request
    order, of each result — the bytes read or None for a write, passed through ``convert(position, result)`` when
    given — or the exception that ended that transfer.

    A backup reads hundreds of objects; one future per object would cost more client time than the frames.
    ``on_each(position, outcome)`` runs as each transfer ends (on the bus reader thread: keep it short).
    ``cancel()`` drops the transfers not yet sent; their outcome is a ``CancelledError``. A transfer that times out
    drops the rest the same way: a drive that stopped answering would otherwise cost a timeout per object.
    """

    def __init__(
        self,
        count: int,
        convert: Callable[[int, bytes], object] | None = None,
        on_each: Callable[[int, object], None] | None = None,
    ) -> None:
        self.future: Future = Future()
        self.future.set_running_or_notify_cancel()
        self._outcomes: list[object] = [None] * count
        self._left = count
        self._convert = convert
        self._on_each = on_each
        self._cancelled = False
        self._lock = threading.Lock()
        if count == 0:
            self.future.set_result([])

    def cancel(self) -> None:
        self._cancelled = True

    def start(self, slot: int) -> bool:
        return not self._cancelled

    def drive_silent(self) -> None:
        """A transfer timed out: the drive stopped answering, the transfers still queued are dropped."""
        self._cancelled = True

    def done(self, slot: int, outcome: object) -> None:
        if not isinstance(outcome, Exception) and self._convert is not None:
            try:
                outcome = self._convert(slot, outcome)
            except Exception as error:  # ValueError: bytes that are no value; anything else reaches the caller too
                outcome = error
        with self._lock:
            self._outcomes[slot] = outcome
            self._left -= 1
            last = self._left == 0
        try:
            if self._on_each is not None:
                self._on_each(slot, outcome)
        finally:  # a failing callback must not leave the caller waiting forever
            if last:
                self.future.set_result(self._outcomes)


class _Transfer:
    """One SDO transfer and where its state machine stands."""

    __slots__ = (
        "abort_on_timeout",
        "answered",
        "completion",
        "deadline",
        "download",
        "expected_size",
        "index",
        "multiplexer",
        "node",
        "offset",
        "received",
        "repeated",
        "retries",
        "segmented",
        "slot",
        "sub",
        "timeout",
        "toggle",
    )

    def __init__(
        self,
        node: int,
        index: int,
        sub: int,
        timeout: float,
        completion: _FutureCompletion | TransferBatch,
        slot: int = 0,
        download: bytes | None = None,
        abort_on_timeout: bool = True,
        retries: int = 0,
    ) -> None:
        self.node, self.index, self.sub, self.timeout = node, index, sub, timeout
        self.multiplexer = struct.pack("<HB", index, sub)  # index and subindex as every frame of the transfer has them
        self.download = download  # None: upload
        self.completion, self.slot = completion, slot
        self.deadline = 0.0
        self.received = bytearray()
        self.expected_size: int | None = None
        self.toggle = 0
        self.offset = 0
        self.segmented = False
        self.abort_on_timeout = abort_on_timeout
        self.retries = retries  # times the initiate request is sent again when it got no answer at all
        self.answered = False
        self.repeated = False


def _stale(transfer: _Transfer, data: bytes) -> bool:
    """An answer that belongs to an earlier request: a late reply about another object (after a timeout), or a
    second reply to a repeated initiate request while the segments are already running."""
    command = data[0]
    initiate_reply = command >> 5 in (2, 3)
    if (initiate_reply or command == 0x80) and data[1:4] != transfer.multiplexer:
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
        link.after_dispatch(self._hand_over)  # responses arrive on the reader thread: complete after the batch

    # -- public API --------------------------------------------------------------------------------------------
    def upload(
        self,
        node: int,
        index: int,
        sub: int,
        timeout: float | None = None,
        probe: bool = False,
        convert: Callable[[bytes], object] | None = None,
    ) -> Future:
        """Read an object; the future gives its bytes, or ``convert(bytes)`` (a ValueError fails the future).

        A ``probe`` (scan) sends no abort when the node stays silent: there is nobody to tell, and on a slow serial
        link 127 useless abort frames would cost most of a second.
        """
        completion = _FutureCompletion(convert)
        self._submit(
            [
                _Transfer(
                    node,
                    index,
                    sub,
                    timeout or self.timeout,
                    completion,
                    abort_on_timeout=not probe,
                    retries=0 if probe else UPLOAD_RETRIES,
                )
            ]
        )
        return completion.future

    def upload_all(
        self,
        node: int,
        objects: Sequence[tuple[int, int]],
        timeout: float | None = None,
        convert: Callable[[int, bytes], object] | None = None,
        on_each: Callable[[int, object], None] | None = None,
    ) -> TransferBatch:
        """Read many objects of one node, back to back, in order, with one future for all (see `TransferBatch`)."""
        batch = TransferBatch(len(objects), convert, on_each)
        timeout = timeout or self.timeout
        self._submit(
            [
                _Transfer(node, index, sub, timeout, batch, slot, retries=UPLOAD_RETRIES)
                for slot, (index, sub) in enumerate(objects)
            ]
        )
        return batch

    def download_all(
        self,
        node: int,
        writes: Sequence[tuple[int, int, bytes]],
        timeout: float | None = None,
        convert: Callable[[int, None], object] | None = None,
        on_each: Callable[[int, object], None] | None = None,
    ) -> TransferBatch:
        """Write many objects of one node, back to back, in order, with one future for all (see `TransferBatch`)."""
        if any(not data for _, _, data in writes):
            raise ValueError("an SDO download needs at least one byte")
        batch = TransferBatch(len(writes), convert, on_each)
        timeout = timeout or self.timeout
        self._submit(
            [
                _Transfer(node, index, sub, timeout, batch, slot, download=bytes(data))
                for slot, (index, sub, data) in enumerate(writes)
            ]
        )
        return batch

    def download(
        self,
        node: int,
        index: int,
        sub: int,
        data: bytes,
        timeout: float | None = None,
        convert: Callable[[None], object] | None = None,
    ) -> Future:
        """Write an object; the future gives None (or ``convert(None)``) once the drive confirmed."""
        if not data:
            raise ValueError("an SDO download needs at least one byte")
        completion = _FutureCompletion(convert)
        self._submit([_Transfer(node, index, sub, timeout or self.timeout, completion, download=bytes(data))])
        return completion.future

    # -- internals ---------------------------------------------------------------------------------------------
    def _submit(self, transfers: list[_Transfer]) -> None:
        """Queue transfers (all of one node) and start the first if the node is idle."""
        if not transfers:
            return
        node = transfers[0].node
        if not 1 <= node <= 127:
            raise ValueError(f"node ID {node} outside 1..127")
        with self._lock:
            if node not in self._queues:
                self._queues[node] = deque()
                self.link.subscribe(SDO_RESPONSE + node, self._on_response)
            self._queues[node].extend(transfers)
            if node not in self._active:
                self._start_next(node)
        self._hand_over()

    def _start_next(self, node: int) -> None:
        """Start the next queued transfer of ``node`` (lock held); failures to send complete it at once."""
        queue = self._queues[node]
        while queue:
            transfer = queue.popleft()
            if not transfer.completion.start(transfer.slot):  # cancelled before it was sent
                self._finished.append((transfer, CancelledError()))
                continue
            self._active[node] = transfer
            if self._send(transfer, self._initiate(transfer)):
                return
        self._active.pop(node, None)

    def _initiate(self, transfer: _Transfer) -> bytes:
        data = transfer.download
        if data is None:
            return bytes([0x40]) + transfer.multiplexer + bytes(4)
        if len(data) <= 4:
            command = 0x23 | ((4 - len(data)) << 2)
            return bytes([command]) + transfer.multiplexer + data.ljust(4, b"\0")
        transfer.segmented = True
        return bytes([0x21]) + transfer.multiplexer + struct.pack("<I", len(data))

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
            if follow_up is None or not self._send(transfer, follow_up):
                self._start_next(node)

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
            self._expect(transfer, command >> 5 == 2 and data[1:4] == transfer.multiplexer, data)
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
            self._expect(transfer, data[1:4] == transfer.multiplexer, data)
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
            raise SdoError(transfer.node, transfer.index, transfer.sub, f"unexpected SDO response {data.hex(' ')}")

    def _abort(self, transfer: _Transfer, code: int) -> None:
        try:
            frame = bytes([0x80]) + transfer.multiplexer + struct.pack("<I", code)
            self.link.send(SDO_REQUEST + transfer.node, frame)
        except LinkDownError:
            pass

    def _finish(self, transfer: _Transfer, outcome: object) -> None:
        """End the active transfer of its node (lock held); it completes in `_hand_over`, after the node's
        next request has left and the lock is released (conversion and the caller's callbacks then delay neither)."""
        if self._active.get(transfer.node) is transfer:
            del self._active[transfer.node]
        self._finished.append((transfer, outcome))

    def _hand_over(self) -> None:
        """Complete finished transfers (lock not held)."""
        while self._finished:
            try:
                transfer, outcome = self._finished.popleft()
            except IndexError:  # another thread took the last one
                return
            transfer.completion.done(transfer.slot, outcome)

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
                transfer.completion.drive_silent()
                sent = " (request sent twice)" if transfer.repeated else ""
                self._finish(
                    transfer,
                    SdoTimeoutError(
                        transfer.node,
                        transfer.index,
                        transfer.sub,
                        f"no SDO response within {transfer.timeout * 1000:.0f} ms on bus {self.link.name}{sent}",
                    ),
                )
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
                self._finished.append(
                    (
                        transfer,
                        SdoLinkError(
                            transfer.node, transfer.index, transfer.sub, f"bus {self.link.name} lost: {reason}"
                        ),
                    )
                )
        self._hand_over()
