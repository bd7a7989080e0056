"""SDO client engine: expedited and segmented transfers, one at a time per node, all nodes in parallel.

Every transfer is a small state machine driven by the frames the bus link delivers; nothing blocks while a drive
thinks.  A caller gets a ``concurrent.futures.Future`` (``asyncio.wrap_future`` makes it awaitable), so a thread can
wait on it and the event loop never does.  Each node has a queue: the next request to a node leaves the moment the
previous response arrives, from the reader thread itself, so a backup of many drives keeps every drive busy and
the bus full without one thread per drive.  Futures complete after the reader's batch of frames was handled and
the follow-up requests left (``BusLink.after_dispatch``).

A read whose request got no answer at all is sent once more before it times out (reads have no side effect, and
one lost frame should not fail a 400-object backup); writes are never repeated.

Each node's queue has two lanes.  Bulk work — the batches of a backup, a restore or a commission, and the
sequence transfers of a backup — waits in the bulk lane; a single read or write someone waits for (a REST call,
the terminal, the status-word watch) goes to the interactive lane, which the node serves first.  A batch thus
yields to interactive requests between its transfers: a read during ten backups waits for at most the one transfer
on the wire, not for thousands queued before it.

A node's boot-up message (it was reset or powered up again) ends its transfers in progress and queued with
`SdoNodeRestarted`: what they asked was asked of a drive state that no longer exists, and a backup across a reset
would mix values from before and after it.

Every transfer ends by itself — answer, abort, timeout, link lost, bus closed — so a future never stays pending;
waits on futures are still bounded (`settle`, `TransferBatch.outcomes`), as a safety net against a stuck reader.

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
from typing import Any, Generic, TypeVar

from servostudio.drive.abort_codes import abort_text
from servostudio.drive.link import BusLink, LinkDownError
from servostudio.errors import CommunicationError, Conflict, Timeout, Unavailable

SDO_REQUEST = 0x600
SDO_RESPONSE = 0x580
BOOT_UP = 0x700  # + node: the error-control message whose single byte 0 says the node (re)started
DEFAULT_TIMEOUT = 0.5
#: Safety net of every wait on a transfer: the engine ends each transfer itself, but a transfer may wait behind
#: many queued ones of its node, and a stuck reader thread must not hang a request or a job for ever.
SAFETY_WAIT = 120.0
UPLOAD_RETRIES = 1  # a read has no side effect: one lost frame should not fail a 400-object backup
ABORT_TIMEOUT = 0x05040000
ABORT_COMMAND = 0x05040001
ABORT_TOGGLE = 0x05030000

#: What a transfer ends with before conversion: the bytes read, or None for a write. The transfer's direction
#: decides which, so the completions (shared by both directions) take either; the public methods say which.
_Result = Any
R = TypeVar("R")


class SdoError(CommunicationError):
    """An SDO transfer failed; the message names the node and the object."""

    def __init__(self, node: int, index: int, sub: int, reason: str) -> None:
        super().__init__(f"node {node}, object 0x{index:04X},{sub}: {reason}")
        self.node = node
        self.index = index
        self.sub = sub
        self.reason = reason


class SdoAbortError(Conflict, SdoError):
    """The drive refused the transfer with a CiA 301 abort code."""

    def __init__(self, node: int, index: int, sub: int, code: int) -> None:
        super().__init__(node, index, sub, f"{abort_text(code)} (SDO abort 0x{code:08X})")
        self.code = code


class SdoTimeoutError(Timeout, SdoError):
    """The drive did not answer in time (absent, unpowered, or the link is broken)."""


class SdoLinkError(Unavailable, SdoError):
    """The bus went down (or was closed) before or during the transfer."""


class SdoNodeRestarted(SdoError):
    """The node sent its boot-up message while the transfer was in progress or queued: it was reset or power-cycled."""


class OutcomeOverdue(Timeout):
    """A transfer's outcome did not arrive within the safety bound of the wait (the bus reader is stuck)."""


def settle(future: Future[R], seconds: float = SAFETY_WAIT) -> R:
    """The result of a transfer's future, waiting at most ``seconds``; the one bounded wait of the product."""
    try:
        return future.result(seconds)
    except TimeoutError:
        raise OutcomeOverdue(f"no outcome of the transfer within {seconds:.0f} s; the bus reader is stuck") from None


class _FutureCompletion:
    """The outcome of one transfer goes to a future (after ``convert`` of a successful result)."""

    __slots__ = ("convert", "future")

    def __init__(self, convert: Callable[[_Result], object] | None) -> None:
        self.future: Future[object] = Future()
        self.convert = convert

    def start(self, slot: int) -> bool:
        return self.future.set_running_or_notify_cancel()  # from now on cancel() refuses: the outcome is known

    def drive_silent(self) -> None:
        """Nothing more to drop: the transfer itself ends with its timeout."""

    def done(self, slot: int, outcome: _Result | Exception) -> None:
        if self.future.done():
            return
        if not isinstance(outcome, Exception) and self.convert is not None:
            try:
                outcome = self.convert(outcome)
            except Exception as error:  # noqa: BLE001 -- the caller gets any error of convert (ValueError: no value)
                outcome = error
        if isinstance(outcome, Exception):
            self.future.set_exception(outcome)
        else:
            self.future.set_result(outcome)


class TransferBatch(Generic[R]):
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
        convert: Callable[[int, _Result], R] | None = None,
        on_each: Callable[[int, R | Exception], None] | None = None,
    ) -> None:
        self.future: Future[list[R | Exception]] = Future()
        self.future.set_running_or_notify_cancel()
        self.patience = SAFETY_WAIT  # the engine adds the time its own transfers may take
        self._outcomes: list[Any] = [None] * count  # every slot is filled before the future completes
        self._left = count
        self._convert = convert
        self._on_each = on_each
        self._cancelled = False
        self._lock = threading.Lock()
        if count == 0:
            self.future.set_result([])

    def outcomes(self) -> list[R | Exception]:
        """Wait for every transfer of the batch (bounded by ``patience``) and give their outcomes."""
        return settle(self.future, self.patience)

    def cancel(self) -> None:
        self._cancelled = True

    def start(self, slot: int) -> bool:
        return not self._cancelled

    def drive_silent(self) -> None:
        """A transfer timed out: the drive stopped answering, the transfers still queued are dropped."""
        self._cancelled = True

    def done(self, slot: int, outcome: _Result | Exception) -> None:
        if not isinstance(outcome, Exception) and self._convert is not None:
            try:
                outcome = self._convert(slot, outcome)
            except Exception as error:  # noqa: BLE001 -- the caller gets any error of convert (ValueError: no value)
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
        completion: _FutureCompletion | TransferBatch[Any],
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


class _NodeQueue:
    """A node's waiting transfers in two lanes: what someone waits for interactively goes ahead of bulk work, each
    lane in the order it was queued."""

    __slots__ = ("bulk", "interactive")

    def __init__(self) -> None:
        self.interactive: deque[_Transfer] = deque()
        self.bulk: deque[_Transfer] = deque()

    def add(self, transfers: list[_Transfer], bulk: bool) -> None:
        (self.bulk if bulk else self.interactive).extend(transfers)

    def next(self) -> _Transfer | None:
        lane = self.interactive or self.bulk
        return lane.popleft() if lane else None

    def drain(self) -> list[_Transfer]:
        """Every waiting transfer, taken out of the queue (the link is gone)."""
        waiting = [*self.interactive, *self.bulk]
        self.interactive.clear()
        self.bulk.clear()
        return waiting


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
        self._queues: dict[int, _NodeQueue] = {}
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
        bulk: bool = False,
    ) -> Future:
        """Read an object; the future gives its bytes, or ``convert(bytes)`` (a ValueError fails the future).

        A ``probe`` (scan) sends no abort when the node stays silent: there is nobody to tell, and on a slow serial
        link 127 useless abort frames would cost most of a second.  ``bulk`` queues it behind interactive requests,
        as part of a long operation.
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
            ],
            bulk,
        )
        return completion.future

    def upload_all(
        self,
        node: int,
        objects: Sequence[tuple[int, int]],
        timeout: float | None = None,
        convert: Callable[[int, bytes], R] | None = None,
        on_each: Callable[[int, R | Exception], None] | None = None,
    ) -> TransferBatch[R]:
        """Read many objects of one node, back to back, in order, with one future for all (see `TransferBatch`)."""
        batch = TransferBatch(len(objects), convert, on_each)
        timeout = timeout or self.timeout
        batch.patience += len(objects) * timeout * (1 + UPLOAD_RETRIES)
        self._submit(
            [
                _Transfer(node, index, sub, timeout, batch, slot, retries=UPLOAD_RETRIES)
                for slot, (index, sub) in enumerate(objects)
            ],
            bulk=True,
        )
        return batch

    def download_all(
        self,
        node: int,
        writes: Sequence[tuple[int, int, bytes]],
        timeout: float | None = None,
        convert: Callable[[int, None], R] | None = None,
        on_each: Callable[[int, R | Exception], None] | None = None,
    ) -> TransferBatch[R]:
        """Write many objects of one node, back to back, in order, with one future for all (see `TransferBatch`)."""
        if any(not data for _, _, data in writes):
            raise ValueError("an SDO download needs at least one byte")
        batch = TransferBatch(len(writes), convert, on_each)
        timeout = timeout or self.timeout
        batch.patience += len(writes) * timeout
        self._submit(
            [
                _Transfer(node, index, sub, timeout, batch, slot, download=bytes(data))
                for slot, (index, sub, data) in enumerate(writes)
            ],
            bulk=True,
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
        bulk: bool = False,
    ) -> Future:
        """Write an object; the future gives None (or ``convert(None)``) once the drive confirmed (``bulk``: as
        part of a long operation, behind interactive requests)."""
        if not data:
            raise ValueError("an SDO download needs at least one byte")
        completion = _FutureCompletion(convert)
        self._submit([_Transfer(node, index, sub, timeout or self.timeout, completion, download=bytes(data))], bulk)
        return completion.future

    # -- internals ---------------------------------------------------------------------------------------------
    def _submit(self, transfers: list[_Transfer], bulk: bool) -> None:
        """Queue transfers (all of one node) in the lane ``bulk`` names and start the first if the node is idle."""
        if not transfers:
            return
        node = transfers[0].node
        if not 1 <= node <= 127:
            raise ValueError(f"node ID {node} outside 1..127")
        with self._lock:
            if node not in self._queues:
                self._queues[node] = _NodeQueue()
                self.link.subscribe(SDO_RESPONSE + node, self._on_response)
                self.link.subscribe(BOOT_UP + node, self._on_error_control)
            self._queues[node].add(transfers, bulk)
            if node not in self._active:
                self._start_next(node)
        self._hand_over()

    def _start_next(self, node: int) -> None:
        """Start the next queued transfer of ``node`` (lock held); failures to send complete it at once."""
        queue = self._queues[node]
        while (transfer := queue.next()) is not None:
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

    def _on_error_control(self, cob_id: int, data: bytes, timestamp: float) -> None:
        """A boot-up ends the node's transfers (see the module); heartbeats carry another state byte."""
        if data != b"\x00":
            return
        node = cob_id - BOOT_UP
        with self._lock:
            void = [self._active.pop(node)] if node in self._active else []
            void += self._queues[node].drain()
            for transfer in void:
                reason = "the node restarted (boot-up) during the transfer"
                self._finished.append((transfer, SdoNodeRestarted(node, transfer.index, transfer.sub, reason)))
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
            expected = transfer.expected_size
            self._finish(transfer, bytes(transfer.received[:expected] if expected is not None else transfer.received))
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
                pending += queue.drain()
            self._active.clear()
            what = "was closed" if self.link.closed else f"lost: {reason}"
            for transfer in pending:
                error = SdoLinkError(transfer.node, transfer.index, transfer.sub, f"bus {self.link.name} {what}")
                self._finished.append((transfer, error))
        self._hand_over()
