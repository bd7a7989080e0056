"""The common parts of the simulator's byte-stream endpoints (socketcand, the RS-232 link, the PROFIBUS line): a TCP
listener on its own thread, a listener whose connections each get a reader thread, and an output queue drained on
its own thread, so a slow reader never blocks the simulation."""

from __future__ import annotations

import contextlib
import logging
import queue
import socket
import threading
from collections.abc import Callable
from typing import Self

log = logging.getLogger(__name__)

#: How often the accept loop looks at its stop flag.
ACCEPT_POLL = 0.2
#: Chunks queued for an endpoint nobody reads; beyond it they are dropped.
OUTPUT_LIMIT = 100_000


class TcpListener:
    """Accepts connections until stopped and hands each to `_connected`; subclasses say what a connection does."""

    name = "tcp"

    def __init__(self, host: str, port: int) -> None:
        self._listener = socket.create_server((host, port))
        self._listener.settimeout(ACCEPT_POLL)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._accept_loop, name=self.name, daemon=True)

    @property
    def address(self) -> tuple[str, int]:
        host, port = self._listener.getsockname()[:2]
        return host, port

    def start(self) -> Self:
        self._thread.start()
        return self

    def stop(self) -> None:
        self._stop.set()
        if self._thread.is_alive():
            self._thread.join()
        self._listener.close()
        self._close_connections()

    def __enter__(self) -> Self:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()

    def _accept_loop(self) -> None:
        while not self._stop.is_set():
            try:
                connection, peer = self._listener.accept()
            except TimeoutError:
                continue
            except OSError:
                return
            log.info("%s client %s connected", self.name, peer)
            self._connected(connection)

    def _connected(self, connection: socket.socket) -> None:
        raise NotImplementedError

    def _close_connections(self) -> None:
        raise NotImplementedError


class StreamListener(TcpListener):
    """A listener whose every connection is served by `_serve` on a thread of its own, and closed after it."""

    def __init__(self, host: str, port: int) -> None:
        super().__init__(host, port)
        self._connections: list[socket.socket] = []

    def _connected(self, connection: socket.socket) -> None:
        connection.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self._connections.append(connection)
        threading.Thread(target=self._serve_then_close, args=(connection,), name=f"{self.name}-rx", daemon=True).start()

    def _close_connections(self) -> None:
        for connection in list(self._connections):
            close_socket(connection)

    def _serve_then_close(self, connection: socket.socket) -> None:
        try:
            self._serve(connection)
        except OSError:
            pass
        finally:
            if connection in self._connections:
                self._connections.remove(connection)
            close_socket(connection)

    def _serve(self, connection: socket.socket) -> None:
        raise NotImplementedError


class QueuedWriter:
    """Drains bytes to one endpoint on its own thread, so the simulation never blocks on a slow reader."""

    def __init__(self, write: Callable[[bytes], object], name: str) -> None:
        self._write = write
        self._queue: queue.SimpleQueue[bytes | None] = queue.SimpleQueue()
        threading.Thread(target=self._run, name=name, daemon=True).start()

    def put(self, data: bytes) -> None:
        if self._queue.qsize() < OUTPUT_LIMIT:
            self._queue.put(data)

    def close(self) -> None:
        self._queue.put(None)

    def _run(self) -> None:
        while (data := self._queue.get()) is not None:
            try:
                self._write(data)
            except OSError:
                return


def close_socket(connection: socket.socket) -> None:
    with contextlib.suppress(OSError):
        connection.shutdown(socket.SHUT_RDWR)
    connection.close()
