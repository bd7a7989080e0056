"""The identification against simulated drives in this process on hidden seeded plants, the simulator on its own
real-time clock as the server's ``sim`` bus runs it (the SYNC of a TPDO capture is answered at once; on a slow host
virtual time slips behind the wall clock, which the time-free estimator does not mind). Each plant starts midway
between its limit switches, the free travel a user gives the experiment."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, replace

import pytest
from tests.support.axis_bench import AxisBench, connect
from tests.support.embedded_sim import SDO_TIMEOUT

from servostudio.services.audit import acting_as
from servostudio.services.cancel import Cancellation
from servostudio.services.identification import IdentificationRequest, check, identify
from servostudio.sim.drive import make_behaviour
from servostudio.sim.network import SimulatedNetwork
from servostudio.sim.plant import Plant


def hidden_plant(seed: int) -> Plant:
    plant = Plant.from_seed(seed)
    middle = (plant.negative_limit_switch + plant.positive_limit_switch) / 2
    return replace(plant, initial_position=round(middle, 3))


@dataclass
class IdBench(AxisBench):
    level = "expert"

    def identify(self, options: dict | None = None, events: list | None = None) -> dict:
        """The identification as a job runs it, acting as the axis's armed controller."""
        with acting_as(self.controller()):
            chosen = check(self.manager.motion, self.axis, IdentificationRequest(options or {}))
            report = events.append if events is not None else (lambda event: None)
            return identify(self.manager.motion, self.axis, self.drive(), chosen, report, Cancellation())


def open_id_bench(device: str, seed: int) -> IdBench:
    def factory(kind, node_id, store, events):
        # the encoTRive is factory-calibrated; an XtrapulsPac cross-check runs on a commissioned axis
        return make_behaviour(kind, store, hidden_plant(seed), events, kind != "encotrive")

    network = SimulatedNetwork(f"1:{device}", behaviour_factory=factory)
    network.start()
    manager, connection = connect(network, SDO_TIMEOUT)
    return IdBench(connection, network, manager)


@pytest.fixture
def id_bench() -> Iterator:
    opened: list[IdBench] = []

    def make(device: str = "encotrive", seed: int = 1) -> IdBench:
        opened.append(open_id_bench(device, seed))
        return opened[-1]

    yield make
    for bench in opened:
        bench.manager.close_all()
