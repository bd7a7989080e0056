"""The XtrapulsPac RS-232 link as a python-can bus (plugin ``servostudio_rs232``; decisions.md §1).

``can.Bus(interface="servostudio_rs232", channel="/dev/ttyUSB0", baudrate=19200)`` — or any pyserial URL such as
``socket://127.0.0.1:29600`` — gives a bus on which ``canopen`` works unchanged, although the cable reaches only one
drive:

* SDO requests to node n (0x600+n) leave on the redirected channel 0x640+n, which the drive on the cable serves
  itself when n is its own node ID and forwards onto the CAN bus otherwise.  Set ``cable_node`` to address that one
  drive on its default channel instead.
* Redirected responses 0x5C0+n come back presented as 0x580+n, and so does the firmware quirk of a response
  carrying the request identifier (0x600+n or 0x640+n).
* Other frames (NMT, ...) pass unchanged.  The link carries only standard 11-bit data frames.

A lost link (cable or TCP connection gone) raises ``can.CanOperationError``; the owner reopens the bus when the
link returns (see ``servostudio.drive.link``).
"""

from __future__ import annotations

import time
from collections import deque
from typing import Any

import can
import serial

from servostudio.transport.rs232_framing import DRIVE_HEADER, HOST_HEADER, FrameDecoder, encode_frame

SDO_REQUEST = 0x600
SDO_RESPONSE = 0x580
REDIRECT_OFFSET = 0x40
MAX_SWITCH_NODE = 63  # node IDs set by the switches; n+64 is reserved for the redirected channel
READ_SLICE = 0.02  # longest single wait on the port, seconds


def host_to_link(cob_id: int, cable_node: int | None) -> int:
    """Identifier to put on the wire for a frame the host sends."""
    node = cob_id - SDO_REQUEST
    if 1 <= node <= MAX_SWITCH_NODE and node != cable_node:
        return cob_id + REDIRECT_OFFSET
    return cob_id


def link_to_host(cob_id: int) -> int:
    """Identifier under which a frame from the drive is presented to the host (undoes redirection and the quirk)."""
    for base in (SDO_RESPONSE + REDIRECT_OFFSET, SDO_REQUEST, SDO_REQUEST + REDIRECT_OFFSET):
        node = cob_id - base
        if 1 <= node <= MAX_SWITCH_NODE:
            return SDO_RESPONSE + node
    return cob_id


class RS232Bus(can.BusABC):
    """python-can bus over the 12-byte ``'M'``/``'S'`` frames of the XtrapulsPac serial port."""

    def __init__(self, channel: str, baudrate: int = 19200, cable_node: int | None = None, **kwargs: Any) -> None:
        try:
            self._port = serial.serial_for_url(
                channel, baudrate=baudrate, bytesize=8, parity="N", stopbits=1, timeout=0.05, write_timeout=1.0
            )
        except (serial.SerialException, ValueError) as error:
            raise can.CanInitializationError(f"cannot open serial link {channel}: {error}") from error
        self.channel_info = f"XtrapulsPac RS-232 link {channel} @ {baudrate} baud"
        self.cable_node = cable_node
        self._decoder = FrameDecoder(DRIVE_HEADER)
        self._received: deque[can.Message] = deque()
        super().__init__(channel=channel, **kwargs)

    def send(self, msg: can.Message, timeout: float | None = None) -> None:
        if msg.is_extended_id or msg.is_remote_frame or msg.is_error_frame or msg.is_fd:
            raise can.CanOperationError("the RS-232 link carries only standard 11-bit data frames")
        self.send_frame(msg.arbitration_id, bytes(msg.data))

    def send_frame(self, cob_id: int, data: bytes) -> None:
        """Send a standard data frame without building a python-can Message (the SDO engine's hot path)."""
        frame = encode_frame(HOST_HEADER, host_to_link(cob_id, self.cable_node), data)
        try:
            self._port.write(frame)
        except (serial.SerialException, OSError) as error:
            raise can.CanOperationError(f"serial link lost: {error}") from error

    def _recv_internal(self, timeout: float | None) -> tuple[can.Message | None, bool]:
        if not self._received:
            self._read(timeout)
        if self._received:
            return self._received.popleft(), False
        return None, False

    def _read(self, timeout: float | None) -> None:
        # python-can passes the time left, different on every call; changing a real port's timeout is a
        # tcsetattr, so it is set only when it moves by more than a millisecond (python-can loops on None).
        timeout = READ_SLICE if timeout is None else min(timeout, READ_SLICE)
        if self._port.timeout is None or abs(self._port.timeout - timeout) > 1e-3:
            self._port.timeout = timeout
        try:
            chunk = self._port.read(self._decoder.bytes_wanted)
        except (serial.SerialException, OSError) as error:
            raise can.CanOperationError(f"serial link lost: {error}") from error
        for cob_id, data in self._decoder.feed(chunk):
            self._received.append(
                can.Message(
                    arbitration_id=link_to_host(cob_id),
                    data=data,
                    dlc=len(data),
                    is_extended_id=False,
                    timestamp=time.time(),
                    channel=self.channel_info,
                )
            )

    def shutdown(self) -> None:
        super().shutdown()
        self._port.close()
