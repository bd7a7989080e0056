"""SDO server of one channel (CiA 301 §7.2.4): expedited, segmented and block transfers in both directions.

`SdoServer.handle(data, reply)` takes one 8-byte request and answers through `reply(frame)` after the drive-side
response time. The reply path is chosen per request, so the same server answers a request from the CAN bus on the
bus and a request from the RS-232 link on the serial line. Block transfers use the CRC-16 of CiA 301
(CCITT polynomial 0x1021, initial value 0), computed over the data bytes only.
"""

from __future__ import annotations

import logging
import struct
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TypeVar

from servostudio.od.model import Variable
from servostudio.sim import sdo_abort
from servostudio.sim.clock import Timer, VirtualClock
from servostudio.sim.frame import Frame
from servostudio.sim.objects import ObjectStore
from servostudio.sim.sdo_abort import SdoAbort

_T = TypeVar("_T")

log = logging.getLogger(__name__)

Reply = Callable[[Frame], None]

DEFAULT_RESPONSE_TIME = 1e-3
"""Drive-side delay between a request and its response, seconds."""
TRANSFER_TIMEOUT = 1.0
"""A segmented or block transfer left waiting this long (virtual seconds) is aborted with 0x05040000."""
SERVER_BLOCK_SIZE = 127

_HEADER = struct.Struct("<BHB")


def crc16_ccitt(data: bytes, crc: int = 0) -> int:
    """CRC-16/XMODEM as CiA 301 block transfers use it."""
    for byte in data:
        crc ^= byte << 8
        for _ in range(8):
            crc = ((crc << 1) ^ 0x1021) if crc & 0x8000 else crc << 1
            crc &= 0xFFFF
    return crc


@dataclass
class _SegmentedDownload:
    var: Variable
    size: int | None
    toggle: int = 0
    data: bytearray = field(default_factory=bytearray)


@dataclass
class _SegmentedUpload:
    data: bytes
    position: int = 0
    toggle: int = 0


@dataclass
class _BlockDownload:
    var: Variable
    size: int | None
    crc_enabled: bool
    data: bytearray = field(default_factory=bytearray)
    expected_seqno: int = 1
    last_segment_received: bool = False
    ending: bool = False


@dataclass
class _BlockUpload:
    data: bytes
    block_size: int
    crc_enabled: bool
    block_start: int = 0
    segments_in_block: int = 0
    started: bool = False
    ending: bool = False


class SdoServer:
    def __init__(
        self,
        store: ObjectStore,
        clock: VirtualClock,
        response_id: int,
        response_time: float = DEFAULT_RESPONSE_TIME,
        completion_delay: Callable[[int, int], float] | None = None,
    ) -> None:
        self.store = store
        self.clock = clock
        self.response_id = response_id
        self.response_time = response_time
        self.completion_delay = completion_delay
        self._transfer: object | None = None
        self._index = 0
        self._sub = 0
        self._reply: Reply = lambda frame: None
        self._timeout: Timer | None = None

    # -- entry point ---------------------------------------------------------------------------------------------

    def handle(self, data: bytes, reply: Reply) -> None:
        data = bytes(data).ljust(8, b"\0")
        self._reply = reply
        try:
            self._dispatch(data)
        except SdoAbort as abort:
            self._abort(abort.code)
        except Exception:  # a failing hook must cost the client one transfer, not stop the simulation
            log.exception("SDO request %s for 0x%04X,%d failed", data.hex(), self._index, self._sub)
            self._abort(sdo_abort.GENERAL)

    def reset(self) -> None:
        """Forget any transfer in progress (NMT reset communication)."""
        self._finish()

    def _dispatch(self, data: bytes) -> None:
        transfer = self._transfer
        command = data[0]
        if isinstance(transfer, _BlockDownload) and not transfer.ending and command != 0x80:
            self._block_download_segment(transfer, data)
            return
        specifier = command >> 5
        if specifier == 4:  # abort from the client: drop the transfer silently
            self._finish()
            return
        handler = {
            0: self._download_segment,
            1: self._initiate_download,
            2: self._initiate_upload,
            3: self._upload_segment,
            5: self._block_upload,
            6: self._block_download,
        }.get(specifier)
        if handler is None:
            raise SdoAbort(sdo_abort.INVALID_COMMAND)
        handler(data)

    # -- helpers -------------------------------------------------------------------------------------------------

    def _send(self, payload: bytes, extra_delay: float = 0.0) -> None:
        frame = Frame(self.response_id, bytes(payload).ljust(8, b"\0"))
        reply = self._reply
        self.clock.call_later(self.response_time + extra_delay, lambda: reply(frame))

    def _header(self, command: int) -> bytes:
        return _HEADER.pack(command, self._index, self._sub)

    def _abort(self, code: int) -> None:
        self._send(self._header(0x80) + struct.pack("<I", code))
        self._finish()

    def _begin(self, transfer: object) -> None:
        self._transfer = transfer
        self._arm_timeout()

    def _arm_timeout(self) -> None:
        if self._timeout is not None:
            self._timeout.cancel()
        self._timeout = self.clock.call_later(TRANSFER_TIMEOUT, lambda: self._abort(sdo_abort.SDO_TIMEOUT))

    def _finish(self) -> None:
        self._transfer = None
        if self._timeout is not None:
            self._timeout.cancel()
            self._timeout = None

    def _expect(self, kind: type[_T]) -> _T:
        """The transfer in progress when it is of `kind`, else the abort a client gets for a stray command."""
        if not isinstance(self._transfer, kind):
            raise SdoAbort(sdo_abort.INVALID_COMMAND, "no matching transfer in progress")
        self._arm_timeout()
        return self._transfer

    def _address(self, data: bytes) -> None:
        _, self._index, self._sub = _HEADER.unpack_from(data)

    def _writable(self) -> Variable:
        var = self.store.variable(self._index, self._sub)
        if not var.access.writable:
            raise SdoAbort(sdo_abort.READ_ONLY)
        return var

    def _store(self, raw: bytes) -> float:
        """Write the received bytes; returns the extra delay before the confirmation (long procedures)."""
        self.store.write_bytes(self._index, self._sub, raw)
        return self.completion_delay(self._index, self._sub) if self.completion_delay else 0.0

    # -- expedited / segmented download ---------------------------------------------------------------------------

    def _initiate_download(self, data: bytes) -> None:
        self._finish()
        self._address(data)
        command = data[0]
        expedited, size_indicated = command & 0x02, command & 0x01
        if expedited:
            length = 4 - ((command >> 2) & 0x03) if size_indicated else None
            var = self.store.variable(self._index, self._sub)
            if length is None:
                length = var.data_type.size or 4
            delay = self._store(data[4 : 4 + length])
            self._send(self._header(0x60), delay)
            return
        var = self._writable()
        size = struct.unpack_from("<I", data, 4)[0] if size_indicated else None
        _check_size(var, size)
        self._begin(_SegmentedDownload(var, size))
        self._send(self._header(0x60))

    def _download_segment(self, data: bytes) -> None:
        transfer = self._expect(_SegmentedDownload)
        command = data[0]
        toggle = command & 0x10
        if toggle != transfer.toggle:
            raise SdoAbort(sdo_abort.TOGGLE_BIT_NOT_ALTERNATED)
        transfer.data += data[1 : 8 - ((command >> 1) & 0x07)]
        transfer.toggle ^= 0x10
        if not command & 0x01:
            self._send(bytes((0x20 | toggle,)))
            return
        if transfer.size is not None and transfer.size != len(transfer.data):
            raise SdoAbort(sdo_abort.LENGTH_MISMATCH, f"announced {transfer.size} bytes, got {len(transfer.data)}")
        self._finish()
        delay = self._store(bytes(transfer.data))
        self._send(bytes((0x20 | toggle,)), delay)

    # -- expedited / segmented upload ------------------------------------------------------------------------------

    def _initiate_upload(self, data: bytes) -> None:
        self._finish()
        self._address(data)
        self._start_upload(self.store.read_bytes(self._index, self._sub))

    def _start_upload(self, value: bytes) -> None:
        if 0 < len(value) <= 4:
            command = 0x43 | ((4 - len(value)) << 2)
            self._send(self._header(command) + value)
            return
        self._begin(_SegmentedUpload(value))
        self._send(self._header(0x41) + struct.pack("<I", len(value)))

    def _upload_segment(self, data: bytes) -> None:
        transfer = self._expect(_SegmentedUpload)
        toggle = data[0] & 0x10
        if toggle != transfer.toggle:
            raise SdoAbort(sdo_abort.TOGGLE_BIT_NOT_ALTERNATED)
        chunk = transfer.data[transfer.position : transfer.position + 7]
        transfer.position += len(chunk)
        transfer.toggle ^= 0x10
        last = transfer.position >= len(transfer.data)
        command = toggle | ((7 - len(chunk)) << 1) | (0x01 if last else 0)
        if last:
            self._finish()
        self._send(bytes((command,)) + chunk)

    # -- block download -------------------------------------------------------------------------------------------

    def _block_download(self, data: bytes) -> None:
        command = data[0]
        if command & 0x01:  # end of block download
            self._block_download_end(data)
            return
        self._finish()
        self._address(data)
        var = self._writable()
        size = struct.unpack_from("<I", data, 4)[0] if command & 0x02 else None
        _check_size(var, size)
        self._begin(_BlockDownload(var, size, crc_enabled=bool(command & 0x04)))
        self._send(self._header(0xA4) + bytes((SERVER_BLOCK_SIZE,)))

    def _block_download_segment(self, transfer: _BlockDownload, data: bytes) -> None:
        self._arm_timeout()
        seqno, last = data[0] & 0x7F, bool(data[0] & 0x80)
        if seqno == 0:
            raise SdoAbort(sdo_abort.INVALID_SEQUENCE_NUMBER)
        if seqno == transfer.expected_seqno and not transfer.last_segment_received:
            transfer.data += data[1:8]
            transfer.expected_seqno += 1
            transfer.last_segment_received = last
        if seqno >= SERVER_BLOCK_SIZE or last:
            acknowledged = transfer.expected_seqno - 1
            transfer.expected_seqno = 1
            transfer.ending = transfer.last_segment_received
            self._send(bytes((0xA2, acknowledged, SERVER_BLOCK_SIZE)))

    def _block_download_end(self, data: bytes) -> None:
        transfer = self._expect(_BlockDownload)
        if not transfer.ending:
            raise SdoAbort(sdo_abort.INVALID_COMMAND, "end of block download before the last segment")
        unused = (data[0] >> 2) & 0x07
        received = bytes(transfer.data[: len(transfer.data) - unused])
        if transfer.size is not None and transfer.size != len(received):
            raise SdoAbort(sdo_abort.LENGTH_MISMATCH, f"announced {transfer.size} bytes, got {len(received)}")
        if transfer.crc_enabled and struct.unpack_from("<H", data, 1)[0] != crc16_ccitt(received):
            raise SdoAbort(sdo_abort.CRC_ERROR)
        self._finish()
        delay = self._store(received)
        self._send(bytes((0xA1,)), delay)

    # -- block upload ---------------------------------------------------------------------------------------------

    def _block_upload(self, data: bytes) -> None:
        subcommand = data[0] & 0x03
        if subcommand == 0:
            self._block_upload_initiate(data)
            return
        transfer = self._expect(_BlockUpload)
        if subcommand == 3 and not transfer.started:
            transfer.started = True
            self._send_block(transfer)
        elif subcommand == 2 and transfer.started and not transfer.ending:
            self._block_upload_ack(transfer, acknowledged=data[1], block_size=data[2])
        elif subcommand == 1 and transfer.ending:
            self._finish()
        else:
            raise SdoAbort(sdo_abort.INVALID_COMMAND)

    def _block_upload_initiate(self, data: bytes) -> None:
        self._finish()
        self._address(data)
        block_size, switch_threshold = data[4], data[5]
        if not 0 < block_size <= 127:
            raise SdoAbort(sdo_abort.INVALID_BLOCK_SIZE)
        value = self.store.read_bytes(self._index, self._sub)
        if switch_threshold and len(value) <= switch_threshold:
            self._start_upload(value)
            return
        self._begin(_BlockUpload(value, block_size, crc_enabled=bool(data[0] & 0x04)))
        self._send(self._header(0xC6) + struct.pack("<I", len(value)))

    def _send_block(self, transfer: _BlockUpload) -> None:
        position = transfer.block_start
        count = 0
        while count < transfer.block_size:
            chunk = transfer.data[position : position + 7]
            position += len(chunk)
            count += 1
            last = position >= len(transfer.data)
            self._send(bytes((count | (0x80 if last else 0),)) + chunk)
            if last:
                break
        transfer.segments_in_block = count

    def _block_upload_ack(self, transfer: _BlockUpload, acknowledged: int, block_size: int) -> None:
        if not 0 < block_size <= 127:
            raise SdoAbort(sdo_abort.INVALID_BLOCK_SIZE)
        if acknowledged > transfer.segments_in_block:
            raise SdoAbort(sdo_abort.INVALID_SEQUENCE_NUMBER)
        transfer.block_start = min(transfer.block_start + 7 * acknowledged, len(transfer.data))
        transfer.block_size = block_size
        complete = acknowledged == transfer.segments_in_block and transfer.block_start >= len(transfer.data)
        if not complete:
            self._send_block(transfer)
            return
        transfer.ending = True
        unused = (7 - len(transfer.data) % 7) % 7 if transfer.data else 7
        crc = crc16_ccitt(transfer.data) if transfer.crc_enabled else 0
        self._send(bytes((0xC1 | (unused << 2),)) + struct.pack("<H", crc))


def _check_size(var: Variable, size: int | None) -> None:
    """Refuse early a segmented/block download whose announced size cannot fit a fixed-size object."""
    expected = var.data_type.size
    if size is None or expected is None or size == expected:
        return
    raise SdoAbort(sdo_abort.LENGTH_TOO_HIGH if size > expected else sdo_abort.LENGTH_TOO_LOW)
