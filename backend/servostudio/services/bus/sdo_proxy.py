"""The SDO server a share's client talks to (``services.bus.share``): CiA 301 expedited and segmented transfers
answered frame by frame, each value read or written by the server's own SDO engine in its turn.

One client may run one transfer per node at a time (as with a real drive); its requests wait in the engine's queue
of that node behind the server's, so the drive sees one SDO client.  A block transfer is refused (abort
0x05040001), which makes python ``canopen`` fall back to a segmented one.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass, field

from servostudio.drive.sdo import SdoAbortError, SdoTimeoutError
from servostudio.errors import RefusedForSafety, ServoStudioError

log = logging.getLogger(__name__)

ABORT_TOGGLE, ABORT_TIMEOUT, ABORT_COMMAND = 0x05030000, 0x05040000, 0x05040001
ABORT_GENERAL, ABORT_STATE = 0x08000000, 0x08000022
Upload = Callable[[int, int, int], bytes]
Write = Callable[[int, int, int, bytes], None]
Answer = Callable[[int, bytes], None]


@dataclass
class _Transfer:
    """A client's segmented transfer in progress with one node."""

    index: int
    sub: int
    upload: bool
    data: bytearray = field(default_factory=bytearray)
    toggle: int = 0


class SdoProxy:
    """The SDO server side of one client: ``upload``/``write`` do the transfer, ``answer`` sends a response frame."""

    def __init__(self, upload: Upload, write: Write, answer: Answer) -> None:
        self._upload_value, self._write_value, self._answer = upload, write, answer
        self._transfers: dict[int, _Transfer] = {}

    def request(self, node: int, request: bytes) -> None:
        """One request frame (8 bytes) of the client to ``node``."""
        command, index, sub = request[0] >> 5, int.from_bytes(request[1:3], "little"), request[3]
        if command == 4:  # abort from the client
            self._transfers.pop(node, None)
        elif command == 2:
            self._upload(node, index, sub)
        elif command == 3:
            self._upload_segment(node, request[0])
        elif command == 1:
            self._download(node, index, sub, request)
        elif command == 0:
            self._download_segment(node, request)
        else:  # block transfers (5, 6): the engine does them for the server, not for a client
            self._abort(node, index, sub, ABORT_COMMAND)

    def _upload(self, node: int, index: int, sub: int) -> None:
        try:
            data = self._upload_value(node, index, sub)
        except Exception as error:  # noqa: BLE001 - every failure is the client's abort
            self._abort(node, index, sub, abort_code(error))
            return
        head = bytes([index & 0xFF, index >> 8, sub])
        if len(data) <= 4:
            self._answer(node, bytes([0x43 | ((4 - len(data)) << 2)]) + head + data.ljust(4, b"\0"))
            return
        self._transfers[node] = _Transfer(index, sub, True, bytearray(data))
        self._answer(node, bytes([0x41]) + head + len(data).to_bytes(4, "little"))

    def _upload_segment(self, node: int, command: int) -> None:
        transfer, toggle = self._transfers.get(node), (command >> 4) & 1
        if transfer is None or not transfer.upload or toggle != transfer.toggle:
            self._out_of_step(node, transfer)
            return
        chunk, transfer.data = bytes(transfer.data[:7]), transfer.data[7:]
        last = not transfer.data
        transfer.toggle ^= 1
        if last:
            del self._transfers[node]
        self._answer(node, bytes([(toggle << 4) | ((7 - len(chunk)) << 1) | int(last)]) + chunk.ljust(7, b"\0"))

    def _download(self, node: int, index: int, sub: int, request: bytes) -> None:
        flags = request[0]
        if flags & 0x02:  # expedited: the value is in this frame
            size = 4 - ((flags >> 2) & 3) if flags & 0x01 else 4
            self._write(node, index, sub, request[4 : 4 + size], bytes([0x60, index & 0xFF, index >> 8, sub]))
            return
        self._transfers[node] = _Transfer(index, sub, False)  # the size it announced is what its segments bring
        self._answer(node, bytes([0x60, index & 0xFF, index >> 8, sub, 0, 0, 0, 0]))

    def _download_segment(self, node: int, request: bytes) -> None:
        transfer, toggle = self._transfers.get(node), (request[0] >> 4) & 1
        if transfer is None or transfer.upload or toggle != transfer.toggle:
            self._out_of_step(node, transfer)
            return
        transfer.data += request[1 : 8 - ((request[0] >> 1) & 7)]
        transfer.toggle ^= 1
        reply = bytes([0x20 | (toggle << 4)])
        if request[0] & 0x01:  # the last segment: the whole value is written now
            del self._transfers[node]
            self._write(node, transfer.index, transfer.sub, bytes(transfer.data), reply)
        else:
            self._answer(node, reply.ljust(8, b"\0"))

    def _write(self, node: int, index: int, sub: int, data: bytes, reply: bytes) -> None:
        """Write the value, then confirm with ``reply`` (or abort with the reason)."""
        try:
            self._write_value(node, index, sub, data)
        except Exception as error:  # noqa: BLE001 - every failure is the client's abort
            self._abort(node, index, sub, abort_code(error))
            return
        self._answer(node, reply.ljust(8, b"\0"))

    def _out_of_step(self, node: int, transfer: _Transfer | None) -> None:
        """A segment without its transfer, or with the wrong toggle bit: the transfer ends with an abort."""
        self._transfers.pop(node, None)
        self._abort(node, transfer.index if transfer else 0, transfer.sub if transfer else 0, ABORT_TOGGLE)

    def _abort(self, node: int, index: int, sub: int, code: int) -> None:
        self._answer(node, bytes([0x80, index & 0xFF, index >> 8, sub]) + code.to_bytes(4, "little"))


def abort_code(error: BaseException) -> int:
    """The abort code that tells the client why its transfer failed: the drive's own, a safety refusal, a timeout."""
    if isinstance(error, SdoAbortError):
        return error.code
    if isinstance(error, RefusedForSafety):
        return ABORT_STATE
    if isinstance(error, (SdoTimeoutError, TimeoutError)):
        return ABORT_TIMEOUT
    if not isinstance(error, ServoStudioError):
        log.exception("share: unexpected failure of a client's SDO transfer", exc_info=error)
    return ABORT_GENERAL
