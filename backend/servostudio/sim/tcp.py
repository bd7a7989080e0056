"""A TCP listener on its own thread: the common part of the simulator's socketcand and serial-link endpoints."""

from __future__ import annotations

import logging
import socket
import threading
from typing import Self

log = logging.getLogger(__name__)

#: How often the accept loop looks at its stop flag.
ACCEPT_POLL = 0.2


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
