"""A socketcand client (raw mode) as a python-can bus.

python-can ships one, but it retries a refused connection in a tight loop for 10 s and does not notice when the
server closes the connection (it then returns "no frame" forever).  A communication server must notice a lost
link and reconnect calmly, so this small client raises ``can.CanOperationError`` when the TCP connection ends
and fails fast when the server is not there.

Protocol: server greets ``< hi >``; client ``< open CHANNEL >`` → ``< ok >``; ``< rawmode >`` → ``< ok >``; then the
server sends ``< frame ID SECONDS.MICROS HEXDATA >`` and the client ``< send ID LEN B0 B1 … >``.

Besides python-can's ``recv``, the bus offers ``receive_frames`` (every frame that arrived, as plain tuples) and
``send_frame``: the bus link uses them, so a busy bus costs one parse per TCP read instead of one per frame.
"""

from __future__ import annotations

import re
import select
import socket
import time
from collections import deque
from typing import Any

import can

CONNECT_TIMEOUT = 2.0
_MAX_PENDING_TEXT = 4096
_MESSAGE = re.compile(rb"<([^<>]*)>")
_FRAME = re.compile(rb"<\s*frame\s+([0-9A-Fa-f]{1,8})\s+([0-9]+(?:\.[0-9]*)?)\s*((?:[0-9A-Fa-f]{2}){0,8})\s*>")

Frame = tuple[int, bytes, float, bool]
"""(identifier, data, timestamp, extended) of one received data frame."""


class SocketcandBus(can.BusABC):
    """python-can bus over a socketcand server in raw mode."""

    def __init__(self, channel: str, host: str, port: int, **kwargs: Any) -> None:
        try:
            self._socket = socket.create_connection((host, port), timeout=CONNECT_TIMEOUT)
        except OSError as error:
            raise can.CanInitializationError(f"cannot reach socketcand at {host}:{port}: {error}") from error
        self._socket.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self._text = b""
        self._frames: deque[Frame] = deque()
        self.channel_info = f"socketcand {host}:{port}/{channel}"
        try:
            self._expect("hi")
            self._command(f"open {channel}")
            self._expect("ok")
            self._command("rawmode")
            self._expect("ok")
        except (OSError, can.CanError) as error:
            self._socket.close()
            raise can.CanInitializationError(f"socketcand {host}:{port}: handshake failed: {error}") from error
        self._socket.setblocking(False)
        self._frames.extend(_parse_frames(self._text))  # frames that came with the last answer
        self._text = self._text[self._text.rfind(b">") + 1 :]
        super().__init__(channel=channel, **kwargs)

    def send(self, msg: can.Message, timeout: float | None = None) -> None:
        if msg.is_remote_frame or msg.is_error_frame or msg.is_fd:
            raise can.CanOperationError("socketcand raw mode: only data frames are sent by this client")
        self.send_frame(msg.arbitration_id, bytes(msg.data), msg.is_extended_id)

    def send_frame(self, cob_id: int, data: bytes, extended: bool = False) -> None:
        """Send a data frame without building a python-can Message (the SDO engine's hot path)."""
        self._send_text(_send_command(cob_id, data, extended))

    def send_frames(self, frames: list[tuple[int, bytes]]) -> None:
        """Send standard data frames in one TCP write."""
        self._send_text("".join(_send_command(cob_id, data) for cob_id, data in frames))

    def receive_frames(self, timeout: float | None) -> list[Frame]:
        """Every frame received so far, waiting up to ``timeout`` for the first; raises when the link is gone."""
        if self._frames:
            frames = list(self._frames)
            self._frames.clear()
            return frames
        readable, _, _ = select.select([self._socket], [], [], timeout)
        if not readable:
            return []
        self._receive_text()
        end = self._text.rfind(b">")
        if end == -1:
            return []
        frames = _parse_frames(self._text[: end + 1])
        self._text = self._text[end + 1 :]
        return frames

    def _recv_internal(self, timeout: float | None) -> tuple[can.Message | None, bool]:
        if not self._frames:
            self._frames.extend(self.receive_frames(timeout))
        if not self._frames:
            return None, False
        identifier, data, timestamp, extended = self._frames.popleft()
        return can.Message(
            arbitration_id=identifier, data=data, dlc=len(data), timestamp=timestamp, is_extended_id=extended
        ), False

    def shutdown(self) -> None:
        super().shutdown()
        self._socket.close()

    def _command(self, text: str) -> None:
        self._send_text(f"< {text} >")

    def _send_text(self, text: str) -> None:
        try:
            self._socket.sendall(text.encode("ascii"))
        except OSError as error:
            raise can.CanOperationError(f"socketcand connection lost: {error}") from error

    def _expect(self, word: str) -> None:
        """Wait for the handshake answer ``< word >``; anything after it stays in the buffer."""
        deadline = time.monotonic() + CONNECT_TIMEOUT
        while True:
            match = _MESSAGE.search(self._text)
            if match is not None:
                message = match.group(1).decode("ascii", errors="replace").strip()
                if message != word:
                    raise can.CanOperationError(f"expected '< {word} >', got '< {message} >'")
                self._text = self._text[match.end() :]
                return
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                raise can.CanOperationError(f"no '< {word} >' from the server")
            self._socket.settimeout(remaining)
            self._receive_text()

    def _receive_text(self) -> None:
        try:
            chunk = self._socket.recv(65536)
        except (BlockingIOError, InterruptedError):
            return
        except OSError as error:
            raise can.CanOperationError(f"socketcand connection lost: {error}") from error
        if not chunk:
            raise can.CanOperationError("socketcand connection closed by the server")
        self._text += chunk
        if len(self._text) > _MAX_PENDING_TEXT and b"<" not in self._text[-_MAX_PENDING_TEXT:]:
            self._text = b""  # garbage without any message start: drop it rather than grow forever


def _send_command(cob_id: int, data: bytes, extended: bool = False) -> str:
    identifier = f"{cob_id:08X}" if extended else f"{cob_id:03X}"
    return f"< send {identifier} {len(data)} {data.hex(' ').upper()} >" if data else f"< send {identifier} 0 >"


def _parse_frames(text: bytes) -> list[Frame]:
    """Every ``< frame ID SECONDS.MICROS HEXDATA >`` in ``text``; other server messages (errors, echoes) are skipped."""
    return [
        (int(identifier, 16), bytes.fromhex(data.decode()), float(stamp), len(identifier) > 3)
        for identifier, stamp, data in _FRAME.findall(text)
    ]
