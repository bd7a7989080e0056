"""A socketcand client (raw mode) as a python-can bus.

python-can ships one, but it retries a refused connection in a tight loop for 10 s and does not notice when the
server closes the connection (it then returns "no frame" forever).  A communication server must notice a lost
link and reconnect calmly, so this small client raises ``can.CanOperationError`` when the TCP connection ends
and fails fast when the server is not there.

Protocol: server greets ``< hi >``; client ``< open CHANNEL >`` → ``< ok >``; ``< rawmode >`` → ``< ok >``; then the
server sends ``< frame ID SECONDS.MICROS HEXDATA >`` and the client ``< send ID LEN B0 B1 … >``.
"""

from __future__ import annotations

import select
import socket
import time
from collections import deque

import can

CONNECT_TIMEOUT = 2.0
_MAX_PENDING_TEXT = 4096


class SocketcandBus(can.BusABC):
    """python-can bus over a socketcand server in raw mode."""

    def __init__(self, channel: str, host: str, port: int, **kwargs: object) -> None:
        try:
            self._socket = socket.create_connection((host, port), timeout=CONNECT_TIMEOUT)
        except OSError as error:
            raise can.CanInitializationError(f"cannot reach socketcand at {host}:{port}: {error}") from error
        self._socket.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self._text = ""
        self._frames: deque[can.Message] = deque()
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
        super().__init__(channel=channel, **kwargs)

    def send(self, msg: can.Message, timeout: float | None = None) -> None:
        if msg.is_remote_frame or msg.is_error_frame or msg.is_fd:
            raise can.CanOperationError("socketcand raw mode: only data frames are sent by this client")
        self.send_frame(msg.arbitration_id, bytes(msg.data), msg.is_extended_id)

    def send_frame(self, cob_id: int, data: bytes, extended: bool = False) -> None:
        """Send a data frame without building a python-can Message (the SDO engine's hot path)."""
        identifier = f"{cob_id:08X}" if extended else f"{cob_id:03X}"
        self._command(f"send {identifier} {len(data)} {data.hex(' ').upper()}".rstrip())

    def _recv_internal(self, timeout: float | None) -> tuple[can.Message | None, bool]:
        if not self._frames:
            self._read(timeout)
        if self._frames:
            return self._frames.popleft(), False
        return None, False

    def shutdown(self) -> None:
        super().shutdown()
        self._socket.close()

    def _command(self, text: str) -> None:
        try:
            self._socket.sendall(f"< {text} >".encode("ascii"))
        except OSError as error:
            raise can.CanOperationError(f"socketcand connection lost: {error}") from error

    def _expect(self, word: str) -> None:
        deadline = time.monotonic() + CONNECT_TIMEOUT
        while True:
            message = self._take_message()
            if message is not None:
                if message != word:
                    raise can.CanOperationError(f"expected '< {word} >', got '< {message} >'")
                return
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                raise can.CanOperationError(f"no '< {word} >' from the server")
            self._socket.settimeout(remaining)
            self._receive_text()

    def _read(self, timeout: float | None) -> None:
        readable, _, _ = select.select([self._socket], [], [], timeout)
        if not readable:
            return
        self._receive_text()
        while (message := self._take_message()) is not None:
            frame = _parse_frame(message)
            if frame is not None:
                self._frames.append(frame)

    def _receive_text(self) -> None:
        try:
            chunk = self._socket.recv(4096)
        except (BlockingIOError, InterruptedError):
            return
        except OSError as error:
            raise can.CanOperationError(f"socketcand connection lost: {error}") from error
        if not chunk:
            raise can.CanOperationError("socketcand connection closed by the server")
        self._text += chunk.decode("ascii", errors="replace")
        if len(self._text) > _MAX_PENDING_TEXT and "<" not in self._text[-_MAX_PENDING_TEXT:]:
            self._text = ""

    def _take_message(self) -> str | None:
        start = self._text.find("<")
        end = self._text.find(">", start + 1)
        if start == -1 or end == -1:
            return None
        message = self._text[start + 1 : end].strip()
        self._text = self._text[end + 1 :]
        return message


def _parse_frame(message: str) -> can.Message | None:
    """``frame ID SECONDS.MICROS HEXDATA`` → Message; other server messages (errors, echoes) are ignored."""
    parts = message.split()
    if len(parts) < 3 or parts[0] != "frame":
        return None
    try:
        identifier = int(parts[1], 16)
        timestamp = float(parts[2])
        data = bytes.fromhex(parts[3]) if len(parts) > 3 else b""
    except ValueError:
        return None
    return can.Message(arbitration_id=identifier, data=data, dlc=len(data), timestamp=timestamp,
                       is_extended_id=len(parts[1]) > 3)
