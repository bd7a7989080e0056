"""A TCP relay between the product and a simulator endpoint, which a test disturbs on purpose: noise inserted into
the byte stream towards the product, bytes corrupted in place, or the connection cut.

The relay owns no protocol: it forwards bytes.  With the RS-232 link (``serial:socket://…``) through it, the
product's frame decoder meets exactly what a noisy cable delivers.
"""

from __future__ import annotations

import contextlib
import socket
import threading


class TcpRelay:
    """``127.0.0.1:port`` → ``target``; `insert` and `corrupt` act on the bytes going back to the client."""

    def __init__(self, target: tuple[str, int]) -> None:
        self.target = target
        self._listener = socket.create_server(("127.0.0.1", 0))
        self.port = self._listener.getsockname()[1]
        self._lock = threading.Lock()
        self._noise = b""
        self._corrupt = 0
        self.disturbed = 0  # bytes inserted or corrupted so far, counted as they go to the client
        self._sockets: list[socket.socket] = []
        threading.Thread(target=self._accept, daemon=True).start()

    def insert(self, noise: bytes) -> None:
        """Send ``noise`` to the client before the next bytes from the server (between two of its frames)."""
        with self._lock:
            self._noise += noise

    def corrupt(self, count: int) -> None:
        """Invert the next ``count`` bytes from the server (a burst of line noise inside frames)."""
        with self._lock:
            self._corrupt += count

    def quiet(self) -> None:
        """No more noise or corruption from now on."""
        with self._lock:
            self._noise, self._corrupt = b"", 0

    def cut(self) -> None:
        """Drop the connections (the listener stays: the client reconnects to the same port)."""
        with self._lock:
            sockets, self._sockets = self._sockets, []
        for sock in sockets:
            with contextlib.suppress(OSError):
                sock.shutdown(socket.SHUT_RDWR)
            sock.close()

    def close(self) -> None:
        self._listener.close()
        self.cut()

    def _accept(self) -> None:
        while True:
            try:
                client, _ = self._listener.accept()
            except OSError:
                return
            upstream = socket.create_connection(self.target)
            with self._lock:
                self._sockets += [client, upstream]
            threading.Thread(target=self._pump, args=(client, upstream, False), daemon=True).start()
            threading.Thread(target=self._pump, args=(upstream, client, True), daemon=True).start()

    def _pump(self, source: socket.socket, sink: socket.socket, to_client: bool) -> None:
        with contextlib.suppress(OSError):
            while data := source.recv(4096):
                sink.sendall(self._disturbed(data) if to_client else data)
        with contextlib.suppress(OSError):
            sink.shutdown(socket.SHUT_WR)

    def _disturbed(self, data: bytes) -> bytes:
        with self._lock:
            noise, self._noise = self._noise, b""
            count = min(self._corrupt, len(data))
            self._corrupt -= count
            self.disturbed += len(noise) + count
        return noise + bytes(byte ^ 0xFF for byte in data[:count]) + data[count:]
