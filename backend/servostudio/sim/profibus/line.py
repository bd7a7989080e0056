"""A PROFIBUS-DP line with simulated TTA-PRO slaves: one virtual clock, and ports through which bytes come in
and go out.

Each port (a TCP connection, the pseudo-terminal, a test) has its own telegram decoder; every telegram a port
brings is offered to each station at the present virtual time, and the responses go to every port, as every
device on an RS-485 segment hears them. The line's baud rate is not modelled: a response is ready as soon as its
request is complete.

Time runs like the CANopen simulator's (`servostudio.sim.network`): tests call `advance(seconds)`; servers call
`start()`, a thread that keeps virtual time on the wall clock (at most `MAX_LAG` behind, slipping rather than
catching up in a burst). `lock` guards everything; ports take it for each batch of telegrams.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable

from servostudio.sim.clock import CONTROL_PERIOD, VirtualClock
from servostudio.sim.profibus.slave import TtaProSlave
from servostudio.transport.profibus.telegram import Frame, encode
from servostudio.transport.profibus.telegram_decoder import TelegramDecoder

log = logging.getLogger(__name__)

PACE = 1e-3
"""Wall-clock seconds between two catch-ups of the real-time thread."""
MAX_LAG = 0.05


class Port:
    """One byte stream into the line."""

    def __init__(self, line: ProfibusLine, write: Callable[[bytes], None]) -> None:
        self.line = line
        self.write = write
        self.decoder = TelegramDecoder()

    def feed(self, data: bytes) -> None:
        frames = self.decoder.feed(data)
        if frames:
            self.line.handle(frames)

    def line_idle(self) -> None:
        self.decoder.line_idle()

    def close(self) -> None:
        self.line.close_port(self)


class ProfibusLine:
    def __init__(self, slaves: list[TtaProSlave]) -> None:
        self.lock = threading.RLock()
        self.clock = VirtualClock()
        self.slaves = {slave.address: slave for slave in slaves}
        self._ports: list[Port] = []
        self._ticks = 0
        self._thread: threading.Thread | None = None
        self._stop = threading.Event()
        self.clock.call_at(CONTROL_PERIOD, self._tick)

    # -- ports --------------------------------------------------------------------------------------------------

    def open_port(self, write: Callable[[bytes], None]) -> Port:
        port = Port(self, write)
        with self.lock:
            self._ports.append(port)
        return port

    def close_port(self, port: Port) -> None:
        with self.lock:
            if port in self._ports:
                self._ports.remove(port)

    def handle(self, frames: list[Frame]) -> None:
        """Telegrams from a port, answered at the present virtual time."""
        with self.lock:
            responses = [self._answer(frame) for frame in frames]
            data = b"".join(encode(response) for response in responses if response is not None)
            ports = list(self._ports)
        if data:
            for port in ports:
                port.write(data)

    def _answer(self, frame: Frame) -> Frame | None:
        response = None
        for slave in self.slaves.values():
            response = slave.station.handle(frame, self.clock.now) or response
        return response

    # -- time ---------------------------------------------------------------------------------------------------

    def _tick(self) -> None:
        self._ticks += 1
        self.clock.call_at((self._ticks + 1) * CONTROL_PERIOD, self._tick)  # first, so a failing step cannot stop time
        now = self.clock.now
        for slave in self.slaves.values():
            slave.step(now)

    @property
    def now(self) -> float:
        return self.clock.now

    def advance(self, seconds: float) -> None:
        """Run `seconds` of virtual time at once (tests; not while `start()`ed)."""
        if self._thread is not None:
            raise RuntimeError("advance() cannot step a line whose real-time thread runs")
        with self.lock:
            self.clock.run_until(self.clock.now + seconds)

    def start(self) -> None:
        if self._thread is None:
            self._stop.clear()
            self._thread = threading.Thread(target=self._run, name="profibus-line", daemon=True)
            self._thread.start()

    def stop(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join()
            self._thread = None

    def _run(self) -> None:
        origin_wall, origin_virtual = time.monotonic(), self.clock.now
        while not self._stop.wait(PACE):
            target = origin_virtual + (time.monotonic() - origin_wall)
            with self.lock:
                self._run_until(target)
                behind = target - self.clock.now
            if behind > MAX_LAG:
                origin_wall += behind - MAX_LAG

    def _run_until(self, target: float) -> None:
        try:
            self.clock.run_until(target)
        except Exception:  # keep the line alive; the failed event is dropped
            log.exception("PROFIBUS simulation event failed at t=%.6f s", self.clock.now)
