"""A server of the tool in this process with a simulated TTA-PRO line opened as bus ``pb`` and a project ``pb``
whose axis X is the TTA-PRO at station 5, for the browser tests that judge the page on the simulated slave itself
(its counter, its state, its EEPROM): the line is the simulator's TCP byte stream (``profibus:tcp:HOST:PORT``),
reached by the project's own DP master."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import httpx
from tests.support.motion_timing import InProcessServer
from tests.support.profibus_line import TtaProLine, ttapro_line

from servostudio.sim.drive.statemachine import State

NODE = 5


@dataclass(frozen=True)
class TtaProServer:
    url: str
    line: TtaProLine

    def api(self, method: str, path: str, **kwargs) -> dict:
        answer = httpx.request(method, f"{self.url}/api{path}", timeout=15, **kwargs)
        assert answer.is_success, answer.text
        return answer.json()

    def counter(self) -> int:
        """The simulated drive's position counter (what PNU 774 reads)."""
        with self.line.line.lock:
            drive = self.line.slaves[NODE].drive
            return drive.units.position(drive.axis.position)

    def drive_state(self) -> State:
        with self.line.line.lock:
            return self.line.slaves[NODE].drive.device.state


@contextmanager
def ttapro_ui_server(root: Path, hold_timeout: float | None = None) -> Iterator[TtaProServer]:
    """The server (the private UI build when ``SERVOSTUDIO_TEST_UI`` names one) on a free port, stopped on exit;
    ``hold_timeout`` replaces the hold-to-run watchdog's 0.1 s for a test that is not about its timing."""
    with ttapro_line(NODE) as line:
        running = InProcessServer(root, buses=())
        if hold_timeout is not None:
            running.set_hold_timeout(hold_timeout)
        try:
            yield _with_project(TtaProServer(running.url, line))
        finally:
            running.close()


def _with_project(server: TtaProServer) -> TtaProServer:
    server.api("POST", "/buses", json={"spec": server.line.spec, "id": "pb"})
    bus = {"name": "pb", "interface": server.line.spec}
    created = server.api("POST", "/projects", json={"name": "pb", "buses": [bus]})
    axis = {"name": "X", "device": "ttapro", "node_id": NODE, "bus": "pb", "revision": created["revision"]}
    server.api("POST", "/projects/pb/axes", json=axis)
    return server
