"""The simulated PROFIBUS line as a raw TCP byte stream (pyserial `socket://HOST:PORT`) or a pseudo-terminal in raw
mode, like the XtrapulsPac RS-232 link (`servostudio.sim.serial_link`). A reader that sees no byte for `IDLE_TIME`
tells its decoder the line is idle, which drops a telegram whose end never came (the sync time of a real line).
Output goes through `sim.tcp.QueuedWriter`, so a slow reader never blocks the simulation.
"""

from __future__ import annotations

import os
import select
import socket
import threading
import tty
from collections.abc import Callable

from servostudio.sim.profibus.line import Port, ProfibusLine
from servostudio.sim.tcp import QueuedWriter, StreamListener

IDLE_TIME = 0.02
"""Seconds without a byte after which a partial telegram is dropped."""
READ_SIZE = 4096


def _read_loop(port: Port, wait: Callable[[float], bool], read: Callable[[], bytes], stop: threading.Event) -> None:
    """Feed the port until end of stream or `stop`; an idle pause lets the decoder drop a partial telegram."""
    while not stop.is_set():
        if not wait(IDLE_TIME):
            if port.decoder.pending:
                port.line_idle()
            continue
        data = read()
        if not data:
            return
        port.feed(data)


class ProfibusTcpServer(StreamListener):
    """Every connection is a port of the line and sees every response on it."""

    name = "profibus-tcp"

    def __init__(self, line: ProfibusLine, host: str = "127.0.0.1", port: int = 0) -> None:
        super().__init__(host, port)
        self.line = line

    def _serve(self, connection: socket.socket) -> None:
        writer = QueuedWriter(connection.sendall, "profibus-tcp-tx")
        port = self.line.open_port(writer.put)
        try:
            _read_loop(
                port, lambda timeout: _readable(connection, timeout), lambda: connection.recv(READ_SIZE), self._stop
            )
        finally:
            port.close()
            writer.close()


class ProfibusPty:
    """The line as a pseudo-terminal; open `path` with pyserial (pyprofibus's serial PHY) like an RS-485 port."""

    def __init__(self, line: ProfibusLine) -> None:
        self.line = line
        self._master, self._slave = os.openpty()
        tty.setraw(self._slave)
        self.path = os.ttyname(self._slave)
        self._stop = threading.Event()
        self._writer = QueuedWriter(lambda data: os.write(self._master, data), "profibus-pty-tx")
        self._port = line.open_port(self._writer.put)
        self._thread = threading.Thread(target=self._read, name="profibus-pty-rx", daemon=True)

    def start(self) -> ProfibusPty:
        self._thread.start()
        return self

    def stop(self) -> None:
        self._stop.set()
        self._port.close()
        self._writer.close()
        if self._thread.is_alive():
            self._thread.join()
        os.close(self._master)
        os.close(self._slave)

    def _read(self) -> None:
        try:
            _read_loop(self._port, lambda timeout: _readable(self._master, timeout), self._read_chunk, self._stop)
        except OSError:
            return

    def _read_chunk(self) -> bytes:
        return os.read(self._master, READ_SIZE)


def _readable(source: socket.socket | int, timeout: float) -> bool:
    return bool(select.select([source], [], [], timeout)[0])
