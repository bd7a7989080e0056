"""TCP server speaking the socketcand protocol (raw mode), as python-can's `socketcand` interface uses it.

Session: server `< hi >`; client `< open CHANNEL >` → `< ok >` (or `< error … >` for another channel name);
client `< rawmode >` → `< ok >`; then the client sends `< send ID LEN B0 B1 … >` (hex, an 8-digit ID is extended)
and receives every bus frame as `< frame ID SECONDS.MICROSECONDS HEXDATA >` with the virtual time stamp. Each
connection is a station on the virtual bus (it does not receive its own frames, it does see other clients').

python-can reads each handshake answer with a single `recv`, so bus frames start flowing `SETTLE_TIME` after the
`< ok >` of raw mode (frames of that interval are queued, not lost).
"""

from __future__ import annotations

import contextlib
import queue
import select
import socket
import threading
import time

from servostudio.sim.frame import Frame
from servostudio.sim.network import SimulatedNetwork
from servostudio.sim.tcp import TcpListener

DEFAULT_PORT = 29536
DEFAULT_CHANNEL = "can0"
SETTLE_TIME = 0.1
OUTPUT_QUEUE_LIMIT = 100_000  # frames waiting for a client that does not read; beyond it they are dropped
WRITE_POLL = 0.2  # how often a writer blocked by a client that does not read looks whether the session closed
_MAX_COMMAND = 256


def format_frame(frame: Frame, timestamp: float) -> str:
    can_id = f"{frame.can_id:08X}" if frame.extended else f"{frame.can_id:03X}"
    return f"< frame {can_id} {timestamp:.6f} {frame.data.hex().upper()} >"


def parse_send(arguments: list[str]) -> Frame:
    """`["601", "8", "40", "18", ...]` -> Frame; ValueError with the reason when malformed."""
    if len(arguments) < 2:
        raise ValueError("send needs an identifier and a length")
    can_id, length = int(arguments[0], 16), int(arguments[1], 16)
    data = bytes([int(byte, 16) for byte in arguments[2:]])
    if length != len(data):
        raise ValueError(f"length {length} but {len(data)} data bytes")
    return Frame(can_id, data, extended=len(arguments[0]) == 8)


class SocketcandServer(TcpListener):
    """The simulated bus as a socketcand server: each client opens the channel and exchanges frames in raw mode."""

    name = "socketcand"

    def __init__(
        self,
        network: SimulatedNetwork,
        host: str = "127.0.0.1",
        port: int = DEFAULT_PORT,
        channel: str = DEFAULT_CHANNEL,
    ) -> None:
        super().__init__(host, port)
        self.network = network
        self.channel = channel
        self._sessions: list[_Session] = []

    def _connected(self, connection: socket.socket) -> None:
        session = _Session(self, connection)
        self._sessions.append(session)
        session.start()

    def _close_connections(self) -> None:
        for session in list(self._sessions):
            session.close()

    def _forget(self, session: _Session) -> None:
        if session in self._sessions:
            self._sessions.remove(session)


class _Session:
    """One client connection: its commands are read on the simulation thread (`SimulatedNetwork.watch`), a writer
    thread drains the output queue.

    A bus frame is sent straight from the simulation thread when nothing is waiting in the queue (a non-blocking
    send: one thread hand-over less per frame, which is most of an SDO round trip's host latency); when the socket
    would block, or while earlier output is still queued, it goes through the queue, so the order is kept.
    """

    def __init__(self, server: SocketcandServer, connection: socket.socket) -> None:
        self.server = server
        self.connection = connection
        connection.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self._output: queue.SimpleQueue[bytes | float | None] = queue.SimpleQueue()
        self._queued = 0  # items put in the output queue and not yet written (guarded by _queued_lock)
        self._queued_lock = threading.Lock()
        self._opened = False
        self._attached = False
        self._closed = threading.Event()
        self._buffer = ""

    def start(self) -> None:
        threading.Thread(target=self._write_loop, name="socketcand-tx", daemon=True).start()
        self._put("< hi >")
        self.server.network.watch(self.connection, self._on_readable)

    def close(self) -> None:
        if self._closed.is_set():
            return
        self._closed.set()
        if self._attached:
            self.server.network.detach(self)
        self._output.put(None)
        with contextlib.suppress(OSError):
            self.connection.shutdown(socket.SHUT_RDWR)
        self.server.network.unwatch_and_close(self.connection)
        self.server._forget(self)

    # -- station --------------------------------------------------------------------------------------------------

    def receive(self, frame: Frame, timestamp: float) -> None:
        data = format_frame(frame, timestamp).encode("ascii")
        with self._queued_lock:
            if self._queued == 0:
                try:
                    data = data[self.connection.send(data, socket.MSG_DONTWAIT) :]
                except BlockingIOError:
                    pass
                except OSError:
                    return  # the connection is gone; the next read closes the session
                if not data:
                    return
            if self._queued >= OUTPUT_QUEUE_LIMIT:
                return
            self._queued += 1
        self._output.put(data)

    def _put(self, item: str | float) -> None:
        """Queue a protocol answer or a pause for the writer thread."""
        with self._queued_lock:
            self._queued += 1
        self._output.put(item.encode("ascii") if isinstance(item, str) else item)

    # -- threads --------------------------------------------------------------------------------------------------

    def _write_loop(self) -> None:
        while True:
            item = self._output.get()
            if item is None:
                return
            try:
                if isinstance(item, float):
                    time.sleep(item)
                else:
                    self._send_all(item)
            except OSError:
                self.close()
                return
            finally:
                with self._queued_lock:
                    self._queued -= 1

    def _send_all(self, data: bytes) -> None:
        """`sendall` for the non-blocking socket: wait until it can take more (OSError once it is closed)."""
        while data:
            try:
                data = data[self.connection.send(data) :]
            except BlockingIOError:
                select.select([], [self.connection], [], WRITE_POLL)
                if self._closed.is_set():
                    raise OSError("session closed") from None

    def _on_readable(self) -> None:
        try:
            chunk = self.connection.recv(65536)
        except (BlockingIOError, InterruptedError):
            return
        except OSError:
            chunk = b""
        if not chunk:
            self.close()
            return
        self._buffer = self._consume(self._buffer + chunk.decode("ascii", errors="replace"))

    def _consume(self, buffer: str) -> str:
        while True:
            start = buffer.find("<")
            if start == -1:
                return ""
            end = buffer.find(">", start)
            if end == -1:
                return buffer[start:] if len(buffer) - start <= _MAX_COMMAND else ""
            self._command(buffer[start + 1 : end].split())
            buffer = buffer[end + 1 :]

    def _command(self, words: list[str]) -> None:
        if not words:
            return
        verb, arguments = words[0], words[1:]
        if verb == "open":
            if arguments != [self.server.channel]:
                self._put(f"< error could not open bus '{' '.join(arguments)}' >")
                return
            self._opened = True
            self._put("< ok >")
        elif verb == "rawmode" and self._opened:
            self._put("< ok >")
            self._put(SETTLE_TIME)
            if not self._attached:
                self._attached = True
                self.server.network.attach(self)
        elif verb == "send" and self._attached:
            try:
                frame = parse_send(arguments)
            except ValueError as exc:
                self._put(f"< error {exc} >")
                return
            self.server.network.inject(frame, sender=self)
        elif verb == "echo":
            self._put("< echo >")
        else:
            self._put(f"< error unsupported command '{verb}' >")
