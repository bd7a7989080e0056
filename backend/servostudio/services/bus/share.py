"""A bus of the server shared with the user's own CANopen scripts as a socketcand endpoint (raw mode), so python
``canopen`` or python-can run beside the browser on the same adapter (docs/drive-access.md, "Sharing a bus").

Opt-in per bus, loopback addresses only.  A client sees every frame the bus receives except the SDO answers meant
for the server (0x581–0x5FF).  Its SDO requests are not put on the bus as they are: CiA 301 allows one client per
SDO channel, and the server's own transfers (the browser's polling) use it all the time.  The share answers them
itself as the drive's SDO server would, each transfer carried out by the server's SDO engine in its turn
(expedited and segmented; a block request is refused with abort 0x05040001, which makes ``canopen`` fall back).
A download passes the motion guard like every other write (an enabling control word needs an armed live client, so
a script is refused with abort 0x08000022).  NMT and SYNC frames go on the bus; the client's other frames (PDOs,
its own heartbeat) are dropped and counted: an RPDO could move an axis past the guard.

Session: ``< hi >``; ``< open CHANNEL >`` → ``< ok >``; ``< rawmode >`` → ``< ok >``; then ``< send ID LEN B… >`` from
the client and ``< frame ID SECONDS.MICROS HEX >`` to it.
"""

from __future__ import annotations

import contextlib
import ipaddress
import socket
import threading
import time
from concurrent.futures import Future
from dataclasses import dataclass
from typing import TYPE_CHECKING

from servostudio.errors import InvalidInput, NotFound, ServoStudioError
from servostudio.services.audit import Actor, acting_as
from servostudio.services.bus.sdo_proxy import SdoProxy

if TYPE_CHECKING:
    from servostudio.services.bus.connections import BusConnection


CHANNEL = "can0"
SDO_REQUEST, SDO_RESPONSE = 0x600, 0x580
PASSED = {0x000, 0x080}  # NMT, SYNC
UPLOAD_WAIT = 30.0  # seconds; the engine ends every transfer itself well before (timeout, link lost)
_MAX_COMMAND = 256


class NotShared(NotFound):
    """The bus has no socketcand endpoint."""


class ShareRefused(InvalidInput):
    """A share asked for on an address that is not a loopback address, or a port that cannot be bound."""


@dataclass
class ShareStatus:
    bus: str
    host: str
    port: int
    channel: str
    clients: int
    dropped: int

    def as_dict(self) -> dict[str, object]:
        return self.__dict__.copy()


def loopback(host: str) -> str:
    """The host, when it is a loopback address (the share gives raw bus access to whoever connects)."""
    try:
        if ipaddress.ip_address(host).is_loopback:
            return host
    except ValueError:
        if host == "localhost":
            return "127.0.0.1"
    raise ShareRefused(f"a bus is shared on a loopback address only (127.0.0.1, ::1), not {host!r}")


class BusShare:
    """The socketcand endpoint of one open bus (reads through its SDO engine, writes through its gated drives)."""

    def __init__(self, connection: BusConnection, host: str, port: int) -> None:
        self.connection, self.bus, self.link = connection, connection.id, connection.link
        self.dropped = 0
        self._sessions: list[_Session] = []
        self._lock = threading.Lock()
        try:
            self._listener = socket.create_server((loopback(host), port), family=_family(host))
        except OSError as error:
            raise ShareRefused(f"bus {self.bus} cannot be shared on {host}:{port}: {error.strerror}") from None
        self.host, self.port = self._listener.getsockname()[:2]
        self._cob_ids = [cob for cob in range(0x800) if not SDO_RESPONSE < cob < SDO_REQUEST]
        for cob in self._cob_ids:
            self.link.subscribe(cob, self._on_frame)
        threading.Thread(target=self._accept, name=f"share {self.bus}", daemon=True).start()

    def status(self) -> ShareStatus:
        return ShareStatus(self.bus, self.host, self.port, CHANNEL, len(self._sessions), self.dropped)

    def close(self) -> None:
        for cob in self._cob_ids:
            self.link.unsubscribe(cob, self._on_frame)
        with contextlib.suppress(OSError):
            self._listener.close()
        for session in list(self._sessions):
            session.close()

    def _accept(self) -> None:
        while True:
            try:
                connection, peer = self._listener.accept()
            except OSError:
                return  # closed
            session = _Session(self, connection, f"{peer[0]}:{peer[1]}")
            with self._lock:
                self._sessions.append(session)
            session.start()

    def _forget(self, session: _Session) -> None:
        with self._lock:
            if session in self._sessions:
                self._sessions.remove(session)

    def _on_frame(self, cob_id: int, data: bytes, timestamp: float) -> None:
        """A frame the bus received (bus reader thread): to every client in raw mode."""
        for session in tuple(self._sessions):
            session.frame(cob_id, data, timestamp)


def _family(host: str) -> socket.AddressFamily:
    return socket.AF_INET6 if ":" in host else socket.AF_INET


class _Session:
    """One client: its commands are read on a thread of its own; frames to it are sent under a lock."""

    def __init__(self, share: BusShare, connection: socket.socket, peer: str) -> None:
        self.share, self.connection, self.peer = share, connection, peer
        connection.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self._send_lock = threading.Lock()
        self._raw = False
        self._opened = False
        self.actor = Actor(user=f"socketcand {share.bus} {peer}", level="expert")
        self._sdo = SdoProxy(self._upload, self._write, self._answer)

    def start(self) -> None:
        self._send("< hi >")
        threading.Thread(target=self._read, name=f"share {self.share.bus} {self.peer}", daemon=True).start()

    def close(self) -> None:
        self._raw = False
        with contextlib.suppress(OSError):
            self.connection.shutdown(socket.SHUT_RDWR)
        with contextlib.suppress(OSError):
            self.connection.close()
        self.share._forget(self)

    def frame(self, cob_id: int, data: bytes, timestamp: float) -> None:
        if self._raw:
            self._send(f"< frame {cob_id:03X} {timestamp:.6f} {data.hex().upper()} >")

    def _send(self, text: str) -> None:
        try:
            with self._send_lock:
                self.connection.sendall(text.encode("ascii"))
        except OSError:
            self.close()

    # -- commands -------------------------------------------------------------------------------------------------

    def _read(self) -> None:
        buffer = ""
        while True:
            try:
                chunk = self.connection.recv(65536)
            except OSError:
                chunk = b""
            if not chunk:
                self.close()
                return
            buffer += chunk.decode("ascii", errors="replace")
            while (end := buffer.find(">")) != -1:
                start = buffer.find("<")
                if 0 <= start < end:
                    self._command(buffer[start + 1 : end].split())
                buffer = buffer[end + 1 :]
            if len(buffer) > _MAX_COMMAND:
                buffer = ""

    def _command(self, words: list[str]) -> None:
        verb, arguments = (words[0], words[1:]) if words else ("", [])
        if verb == "open":
            self._opened = arguments == [CHANNEL]
            self._send("< ok >" if self._opened else f"< error could not open bus '{' '.join(arguments)}' >")
        elif verb == "rawmode" and self._opened:
            self._send("< ok >")
            self._raw = True
        elif verb == "send" and self._raw:
            self._client_frame(arguments)
        elif verb == "echo":
            self._send("< echo >")
        elif verb:
            self._send(f"< error unsupported command '{verb}' >")

    def _client_frame(self, arguments: list[str]) -> None:
        try:
            cob_id, length = int(arguments[0], 16), int(arguments[1], 16)
            data = bytes(int(byte, 16) for byte in arguments[2:])
        except (IndexError, ValueError):
            self._send("< error malformed send >")
            return
        if length != len(data) or len(data) > 8:
            self._send("< error malformed send >")
        elif SDO_REQUEST < cob_id < SDO_REQUEST + 0x80 and len(data) == 8:
            self._sdo.request(cob_id - SDO_REQUEST, data)
        elif cob_id in PASSED:
            with contextlib.suppress(ServoStudioError):
                self.share.link.send(cob_id, data)
        else:
            self.share.dropped += 1

    # -- what the client's SDO transfers do on the bus ----------------------------------------------------------

    def _upload(self, node: int, index: int, sub: int) -> bytes:
        future: Future = self.share.connection.engine.upload(node, index, sub)
        return bytes(future.result(timeout=UPLOAD_WAIT))

    def _write(self, node: int, index: int, sub: int, data: bytes) -> None:
        """Through the motion guard and the audit log, as the share's client."""
        with acting_as(self.actor):
            self.share.connection.drive(node).write_raw_bytes(index, sub, data)

    def _answer(self, node: int, data: bytes) -> None:
        self._send(f"< frame {SDO_RESPONSE + node:03X} {time.time():.6f} {data.hex().upper()} >")
