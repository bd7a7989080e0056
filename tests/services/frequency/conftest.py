"""Benches for the frequency response: simulated XtrapulsPacs commissioned for HIDDEN seeded plants, in this process,
running in real time as the server's simulator does (faster than the wall clock while nothing streams), and so
locked to the SYNC while the measurement streams its excitation (docs/frequency-response.md §4, sim/sync_lock.py).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass, field

import pytest
from tests.support.axis_bench import AxisBench, connect
from tests.support.plant_truth import free

from servostudio.services.audit import acting_as
from servostudio.services.cancel import Cancellation
from servostudio.services.frequency.measure import MeasureRequest
from servostudio.services.frequency.service import FrequencyRequest, FrequencyService
from servostudio.sim.drive import make_behaviour
from servostudio.sim.network import SimulatedNetwork
from servostudio.sim.plant import Plant

SDO_TIMEOUT = 3.0


@dataclass
class Bench(AxisBench):
    service: FrequencyService = field(default_factory=FrequencyService)

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


def open_bench(plant: Plant, speed: float, device: str = "xtrapulspac") -> Bench:
    """One commissioned drive (node 1, an XtrapulsPac unless ``device`` says otherwise) on ``plant``: gains tuned for
    the plant as a machine in service has."""
    network = SimulatedNetwork(
        f"1:{device}",
        behaviour_factory=lambda device, node, store, events: make_behaviour(device, store, plant, events, True),
    )
    network.start(speed)
    manager, connection = connect(network, SDO_TIMEOUT)
    return Bench(connection, network, manager)


@pytest.fixture
def frequency_bench() -> Iterator[Callable[..., Bench]]:
    opened: list[Bench] = []

    def make(plant: Plant, speed: float = 4.0, device: str = "xtrapulspac") -> Bench:
        opened.append(open_bench(free(plant), speed, device))
        return opened[-1]

    yield make
    for bench in opened:
        bench.manager.close_all()
