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
The futures, the batches, the bounded wait and a node's two lanes are ``drive/transfers.py``'s, shared with the PKW
engine; `settle`, `SAFETY_WAIT` and `OutcomeOverdue` are re-exported here, where the engine's callers take them.

Large objects (the recorder's buffer, any DOMAIN of kilobytes) are read by block upload (`upload_block`,
``drive/sdo_block.py``): a block of up to 127 segments per acknowledgement instead of a request per 7 bytes. A node
that refuses block transfers (abort 0x05040001, or an ordinary upload response: CiA 301's protocol switch) is read
by segmented upload in the same transfer, and is not asked for a block again until it restarts. Everything else
stays expedited or segmented: the dictionaries' values fit in one frame or a few segments, where a block transfer
needs more frames.
"""

from __future__ import annotations

import contextlib
import logging
import struct
import threading
import time
from collections import deque
from collections.abc import Callable, Sequence
from concurrent.futures import CancelledError, Future
from typing import TypeVar

from servostudio.drive.abort_codes import abort_text
from servostudio.drive.link import BusLink, LinkDownError
from servostudio.drive.sdo_block import MAX_BLOCK_SIZE, SEGMENT_BYTES, BlockProtocolError, BlockUpload, Step
from servostudio.drive.transfers import SAFETY_WAIT as SAFETY_WAIT
from servostudio.drive.transfers import Completion, FutureCompletion, NodeLanes, TransferBatch
from servostudio.drive.transfers import OutcomeOverdue as OutcomeOverdue
from servostudio.drive.transfers import settle as settle
from servostudio.errors import CommunicationError, Conflict, Timeout, Unavailable

log = logging.getLogger(__name__)

SDO_REQUEST = 0x600
SDO_RESPONSE = 0x580
BOOT_UP = 0x700  # + node: the error-control message whose single byte 0 says the node (re)started
DEFAULT_TIMEOUT = 0.5
UPLOAD_RETRIES = 1  # a read has no side effect: one lost frame should not fail a 400-object backup
ABORT_TIMEOUT = 0x05040000
ABORT_COMMAND = 0x05040001
ABORT_TOGGLE = 0x05030000
ABORT_STOPPED = 0x08000000  # general error: CiA 301 has no code for "the client gave up"
#: ``_advance``'s answer when the server sends more before the client answers (the segments of a block)
_LISTEN = b""
#: segments between two progress reports of a large upload (one block's worth, block or segmented)
PROGRESS_SEGMENTS = MAX_BLOCK_SIZE
#: Safety net of the wait on one large upload: 32 KB by segmented SDO over the 19200-baud RS-232 link take 2 minutes
LARGE_SAFETY_WAIT = 600.0
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


class SdoStopped(SdoError):
    """The client stopped a large upload before it completed (``stop()`` said so); the transfer was aborted."""


class SdoNodeRestarted(SdoError):
    """The node sent its boot-up message while the transfer was in progress or queued: it was reset or power-cycled."""


class _Transfer:
    """One SDO transfer and where its state machine stands."""

    __slots__ = (
        "abort_on_timeout",
        "answered",
        "block",
        "block_size",
        "completion",
        "deadline",
        "download",
        "expected_size",
        "index",
        "multiplexer",
        "node",
        "offset",
        "progress",
        "received",
        "repeated",
        "retries",
        "segmented",
        "slot",
        "stop",
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
        completion: Completion,
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
        self.block: BlockUpload | None = None  # a block upload while the server goes along
        self.block_size = 0  # the block size asked (0: no block upload)
        self.progress: Callable[[int, int | None], None] | None = None
        self.stop: Callable[[], bool] | None = None

    def large(
        self, block_size: int, progress: Callable[[int, int | None], None] | None, stop: Callable[[], bool] | None
    ) -> _Transfer:
        """This upload as a large one: by block (``block_size`` > 0), with progress reports and a way to stop."""
        self.block_size, self.progress, self.stop = block_size, progress, stop
        return self

    @property
    def received_bytes(self) -> int:
        return len(self.block.received) if self.block is not None else len(self.received)


def _stale(transfer: _Transfer, data: bytes) -> bool:
    """An answer that belongs to an earlier request: a late reply about another object (after a timeout), or a
    second reply to a repeated initiate request while the segments are already running."""
    command = data[0]
    if transfer.block is not None:
        return _stale_in_block(transfer, data)
    initiate_reply = command >> 5 in (2, 3)
    if (initiate_reply or command == 0x80) and data[1:4] != transfer.multiplexer:
        return True
    in_segments = transfer.offset > 0 if transfer.download is not None else transfer.segmented
    return initiate_reply and in_segments


def _stale_in_block(transfer: _Transfer, data: bytes) -> bool:
    """In a block upload every frame after the initiate response is a segment or the end (neither names the
    object); only an abort or an initiate response about another object is stale."""
    assert transfer.block is not None
    command = data[0]
    if command == 0x80 or (not transfer.block.started and command >> 5 in (2, 6)):
        return data[1:4] != transfer.multiplexer
    return False


class SdoEngine:
    """All SDO client transfers of one bus."""

    def __init__(self, link: BusLink, timeout: float = DEFAULT_TIMEOUT) -> None:
        self.link = link
        self.timeout = timeout
        self._lock = threading.RLock()  # futures' callbacks may submit the next transfer
        self._queues: dict[int, NodeLanes[_Transfer]] = {}
        self._active: dict[int, _Transfer] = {}
        self._finished: deque[tuple[_Transfer, object]] = deque()  # outcomes to hand over once the lock is free
        self._reports: deque[tuple[Callable[[int, int | None], None], int, int | None]] = deque()  # progress
        self._no_block: set[int] = set()  # nodes that refused a block upload (until they restart)
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
        completion = FutureCompletion(convert)
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
        timeout = timeout or self.timeout
        batch = TransferBatch(len(objects), convert, on_each, each=timeout * (1 + UPLOAD_RETRIES))
        self._submit(
            [
                _Transfer(node, index, sub, timeout, batch, slot, retries=UPLOAD_RETRIES)
                for slot, (index, sub) in enumerate(objects)
            ],
            bulk=True,
        )
        return batch

    def upload_block(
        self,
        node: int,
        index: int,
        sub: int,
        timeout: float | None = None,
        progress: Callable[[int, int | None], None] | None = None,
        stop: Callable[[], bool] | None = None,
        block_size: int = MAX_BLOCK_SIZE,
        bulk: bool = True,
    ) -> Future:
        """Read a large object by block upload (segmented where the node refuses blocks); the future gives the
        bytes. ``progress(received, total)`` runs after each block (total None: not announced), after the bus
        reader's batch; ``stop()`` is asked at the same moments (on the reader thread: a flag, nothing slow) and
        ends the transfer with an abort and `SdoStopped`. ``timeout`` is per frame the client waits for.
        """
        if not 1 <= block_size <= MAX_BLOCK_SIZE:
            raise ValueError(f"block size {block_size} outside 1..{MAX_BLOCK_SIZE}")
        completion = FutureCompletion(None)
        transfer = _Transfer(node, index, sub, timeout or self.timeout, completion, retries=UPLOAD_RETRIES)
        self._submit([transfer.large(0 if node in self._no_block else block_size, progress, stop)], bulk)
        return completion.future

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
        timeout = timeout or self.timeout
        batch = TransferBatch(len(writes), convert, on_each, each=timeout)
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
        completion = FutureCompletion(convert)
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
                self._queues[node] = NodeLanes()
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
        if data is None and transfer.block_size:
            transfer.block = BlockUpload(transfer.block_size)
            return transfer.block.initiate(transfer.multiplexer)
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
            if follow_up is _LISTEN:
                transfer.deadline = time.monotonic() + transfer.timeout
            elif follow_up is None or not self._send(transfer, follow_up):
                self._start_next(node)

    def _on_error_control(self, cob_id: int, data: bytes, timestamp: float) -> None:
        """A boot-up ends the node's transfers (see the module); heartbeats carry another state byte."""
        if data != b"\x00":
            return
        node = cob_id - BOOT_UP
        with self._lock:
            self._no_block.discard(node)  # the node may be another device (or firmware) now
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
            if code == ABORT_COMMAND and transfer.block is not None and not transfer.block.started:
                return self._without_block(transfer)
            raise SdoAbortError(transfer.node, transfer.index, transfer.sub, code)
        if transfer.download is None:
            if transfer.block is not None:
                return self._advance_block(transfer, data)
            return self._advance_upload(transfer, command, data)
        return self._advance_download(transfer, command, data)

    def _without_block(self, transfer: _Transfer) -> bytes:
        """The node refused the block upload: read the object by segmented upload instead (and from now on)."""
        self._no_block.add(transfer.node)
        transfer.block, transfer.block_size = None, 0
        return self._initiate(transfer)

    def _advance_block(self, transfer: _Transfer, data: bytes) -> bytes | None:
        block = transfer.block
        assert block is not None
        try:
            step = block.on_frame(data, transfer.multiplexer)
        except BlockProtocolError as error:
            self._abort(transfer, error.code)
            raise SdoError(transfer.node, transfer.index, transfer.sub, f"block upload: {error}") from None
        if step.switched:  # the server answered with an ordinary upload (protocol switch)
            transfer.block = None
            return self._advance_upload(transfer, data[0], data)
        return self._after_step(transfer, step)

    def _after_step(self, transfer: _Transfer, step: Step) -> bytes | None:
        if step.data is not None:
            self._send_last(transfer, step.reply)
            self._finish(transfer, step.data)
            return None
        if step.block_done:
            self._report(transfer, transfer.block.size if transfer.block is not None else None)
        return _LISTEN if step.reply is None else step.reply

    def _send_last(self, transfer: _Transfer, frame: bytes | None) -> None:
        """The client's last frame of a transfer (no answer comes: a dead link changes nothing any more)."""
        if frame is None:
            return
        with contextlib.suppress(LinkDownError):
            self.link.send(SDO_REQUEST + transfer.node, frame)

    def _report(self, transfer: _Transfer, total: int | None) -> None:
        """Progress of a large upload after a block; the client may stop it here (aborted at once)."""
        if transfer.stop is not None and transfer.stop():
            self._abort(transfer, ABORT_STOPPED)
            raise SdoStopped(transfer.node, transfer.index, transfer.sub, "upload stopped by the client")
        if transfer.progress is not None:
            self._reports.append((transfer.progress, transfer.received_bytes, total))

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
        if transfer.progress is not None and len(transfer.received) % (PROGRESS_SEGMENTS * SEGMENT_BYTES) == 0:
            self._report(transfer, transfer.expected_size)
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
        """Report progress and complete finished transfers (lock not held)."""
        while self._reports:
            try:
                progress, done, total = self._reports.popleft()
            except IndexError:  # another thread took the last one
                break
            try:
                progress(done, total)
            except Exception:  # a failing report must not keep the transfers of the batch from completing
                log.exception("progress report of an SDO upload failed")
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
