"""Measuring a hold-to-run stop on the simulator's clock: a real server in this process, and probes on both ends.

The server (``servostudio.api.app`` under uvicorn, on a thread) runs its ``sim`` bus in this process, so the test
reaches the simulated drive and its ``VirtualClock``.  With ``start()`` the simulator paces virtual time against
``time.monotonic()`` (``sim/network.py``): virtual time runs with the wall clock, at most ``MAX_LAG`` behind it
when the host is slow (then it slips: it runs slower, never faster).  Both instants are taken on that clock:

- :class:`KeepaliveLog` records the virtual time at which each keepalive reached the server (the motion service's
  ``keepalive``, as the event socket calls it): the server thread posts it to the simulator, which stamps it with
  its clock after the chunk it runs (≤ one control period, 250 µs), exactly as it stamps a frame of the quick stop
  when that reaches the bus — both ends on the simulator's own timeline, also when it lags the wall clock;
- :class:`DriveProbe` samples the drive every 0.5 ms of virtual time, on the simulator's own thread: when the
  axis left Operation enabled (the quick stop began) and when its speed fell to standstill.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

import httpx
import uvicorn
from tests.support.access import passwordless
from tests.support.live_server import free_port, private_ui_settings

from servostudio.api.app import Settings, create_app
from servostudio.sim.drive.statemachine import State
from servostudio.sim.network import SimulatedNetwork

PROBE_PERIOD = 0.0005
STANDSTILL = 0.5  # rad/s, the simulated drive's own standstill threshold (``STANDSTILL_SPEED``)


class InProcessServer:
    """``servostudio serve`` with simulated drives (``buses``: the ``sim`` bus by default), on a thread of this
    process (stopped by ``close``)."""

    def __init__(self, root: Path, buses: tuple[str, ...] = ("sim",)) -> None:
        self.port = free_port()
        self.url = f"http://127.0.0.1:{self.port}"
        settings = Settings(
            projects_dir=root / "projects",
            data_dir=passwordless(root / "data"),
            buses=buses,
            port=self.port,
            **private_ui_settings(),
        )
        (root / "projects").mkdir(exist_ok=True)
        self.app = create_app(settings)
        self.server = uvicorn.Server(uvicorn.Config(self.app, host="127.0.0.1", port=self.port, log_level="warning"))
        self.thread = threading.Thread(target=self.server.run, name="test-server", daemon=True)
        self.thread.start()
        deadline = time.monotonic() + 30
        while not self.server.started:
            if time.monotonic() > deadline or not self.thread.is_alive():
                raise RuntimeError("the in-process server did not start")
            time.sleep(0.05)

    @property
    def state(self):
        return self.app.state.server

    @property
    def network(self) -> SimulatedNetwork:
        simulation = self.state.connections.get("sim").simulation
        assert isinstance(simulation, SimulatedNetwork)
        return simulation

    def set_hold_timeout(self, seconds: float) -> None:
        """The hold-to-run watchdog's timeout (0.1 s: ``HOLD_TIMEOUT``), raised by a test of what a held motion does,
        not of the hold's timing: on a loaded host starved keepalives end it early (the safe side)."""
        self.state.motion.motions.holds.timeout = seconds

    def close(self) -> None:
        self.server.should_exit = True
        self.thread.join(timeout=15)

    def open_bus(self, spec: str, bus_id: str) -> InProcessServer:
        """Open ``spec`` as bus ``bus_id`` of the server (a simulated TTA-PRO line's, for example)."""
        opened = httpx.post(f"{self.url}/api/buses", json={"spec": spec, "id": bus_id}, timeout=15)
        assert opened.status_code == 201, opened.text
        return self


@contextmanager
def server_on_bus(root: Path, spec: str, bus_id: str = "pb") -> Iterator[InProcessServer]:
    """An in-process server with ``spec`` opened as bus ``bus_id``, closed on exit."""
    running = InProcessServer(root)
    try:
        yield running.open_bus(spec, bus_id)
    finally:
        running.close()


@dataclass
class KeepaliveLog:
    """Virtual times at which the server received a keepalive that kept a motion alive."""

    network: SimulatedNetwork
    times: list[float] = field(default_factory=list)

    def install(self, server: InProcessServer) -> None:
        motions = server.state.motion.motions
        original = motions.keepalive

        def recorded(client: str, axis: tuple[str, int]) -> bool:
            kept = original(client, axis)
            if kept:  # stamped by the simulator as it gets to it, as it stamps the frames of the stop
                self.network.post(lambda: self.times.append(self.network.clock.now))
            return kept

        motions.keepalive = recorded

    def last(self) -> float:
        assert self.times, "no keepalive reached the server"
        return self.times[-1]


@dataclass
class Sample:
    time: float
    enabled: bool
    speed: float


class DriveProbe:
    """The drive's state and speed every ``PROBE_PERIOD`` of virtual time, sampled on the simulator's thread."""

    def __init__(self, network: SimulatedNetwork, node: int) -> None:
        self.network = network
        self.behaviour = network.node(node).behaviour
        self.samples: list[Sample] = []
        self._running = True
        network.post(self._sample)

    def _sample(self) -> None:
        if not self._running:
            return
        control = self.behaviour.device_control
        enabled = control.state is State.OPERATION_ENABLED
        self.samples.append(Sample(self.network.now, enabled, float(self.behaviour.loops.speed)))
        self.network.clock.call_later(PROBE_PERIOD, self._sample)

    def stop(self) -> None:
        self._running = False

    def was_running(self) -> bool:
        return any(sample.enabled and abs(sample.speed) > STANDSTILL for sample in self.samples)

    def stop_began(self) -> float:
        """The first instant the axis was no longer in Operation enabled after it ran."""
        ran = False
        for sample in self.samples:
            ran = ran or (sample.enabled and abs(sample.speed) > STANDSTILL)
            if ran and not sample.enabled:
                return sample.time
        raise AssertionError("the axis never left Operation enabled")

    def standstill(self) -> float:
        """The first instant at standstill after the stop began."""
        began = self.stop_began()
        for sample in self.samples:
            if sample.time >= began and abs(sample.speed) < STANDSTILL:
                return sample.time
        raise AssertionError("the axis never came to standstill")
