"""Benches for the frequency response: simulated XtrapulsPacs commissioned for HIDDEN seeded plants, in this process,
running in real time as the server's simulator does (faster than the wall clock while nothing streams), and so
locked to the SYNC while the measurement streams its excitation (docs/frequency-response.md §4, sim/sync_lock.py).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass, field, replace

import pytest

from servostudio.drive.access import Drive
from servostudio.services.audit import Actor, acting_as
from servostudio.services.bus import BusConnection, ConnectionManager
from servostudio.services.cancel import Cancellation
from servostudio.services.frequency.measure import MeasureRequest
from servostudio.services.frequency.service import FrequencyRequest, FrequencyService
from servostudio.sim.drive import make_behaviour
from servostudio.sim.network import SimulatedNetwork
from servostudio.sim.plant import Plant

SDO_TIMEOUT = 3.0


def free(plant: Plant) -> Plant:
    """No switches or hard stops: the base speed carries the axis several revolutions."""
    switches = {name: None for name in ("home_switch", "negative_limit_switch", "positive_limit_switch")}
    return replace(plant, **switches, negative_hard_stop=None, positive_hard_stop=None)


@dataclass
class Bench:
    connection: BusConnection
    network: SimulatedNetwork
    manager: ConnectionManager
    service: FrequencyService = field(default_factory=FrequencyService)
    _actor: Actor | None = None

    @property
    def axis(self) -> tuple[str, int]:
        return (self.connection.id, 1)

    def drive(self) -> Drive:
        return self.connection.drive(1)

    def plant(self) -> Plant:
        """The hidden truth (the service never sees it)."""
        with self.network.lock:
            return self.network.node(1).behaviour.plant  # type: ignore[attr-defined]

    def controller(self) -> Actor:
        if self._actor is None:
            guard = self.manager.motion
            self._actor = Actor("tests", "administrator", guard.connect("tests"))
            guard.arm(self._actor, self.axis)
        return self._actor

    def measure(self, cancellation: Cancellation | None = None, **options: object) -> dict:
        request = FrequencyRequest(MeasureRequest(**options))  # type: ignore[arg-type]
        with acting_as(self.controller()):
            return self.service.run(
                self.manager.motion,
                self.connection,
                self.drive(),
                request,
                lambda event: None,
                cancellation or Cancellation(),
            )


def open_bench(plant: Plant, speed: float) -> Bench:
    """One commissioned XtrapulsPac (node 1) on ``plant``: gains tuned for the plant as a machine in service has."""
    network = SimulatedNetwork(
        "1", behaviour_factory=lambda device, node, store, events: make_behaviour(device, store, plant, events, True)
    )
    network.start(speed)
    manager = ConnectionManager()
    manager._opener = lambda spec: (network.open_bus, network)  # type: ignore[method-assign]
    connection = manager.open("sim", wait=5.0)
    assert connection.link.wait_connected(5.0)
    connection.engine.timeout = SDO_TIMEOUT
    return Bench(connection, network, manager)


@pytest.fixture
def frequency_bench() -> Iterator[Callable[..., Bench]]:
    opened: list[Bench] = []

    def make(plant: Plant, speed: float = 4.0) -> Bench:
        opened.append(open_bench(free(plant), speed))
        return opened[-1]

    yield make
    for bench in opened:
        bench.manager.close_all()
