"""One simulated axis (node 1) in this process on a HIDDEN plant, opened through a ``ConnectionManager`` as the
server opens its ``sim`` bus, with the test acting as the axis's armed controller: the bench of the tool-side
procedures that turn the motor (frequency response, identification). ``plant()`` is the truth the tests judge by;
the code under test never sees it."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from servostudio.drive.access import Drive
from servostudio.services.audit import Actor
from servostudio.services.bus import BusConnection, ConnectionManager
from servostudio.sim.network import SimulatedNetwork
from servostudio.sim.plant import Plant


def connect(network: SimulatedNetwork, sdo_timeout: float) -> tuple[ConnectionManager, BusConnection]:
    """A manager whose ``sim`` bus is ``network``, opened and connected, with a patient SDO timeout."""
    manager = ConnectionManager()
    manager._opener = lambda spec: (network.open_bus, network)  # type: ignore[method-assign]
    connection = manager.open("sim", wait=5.0)
    assert connection.link.wait_connected(5.0)
    connection.engine.timeout = sdo_timeout
    return manager, connection


@dataclass
class AxisBench:
    connection: BusConnection
    network: SimulatedNetwork
    manager: ConnectionManager
    #: the level the controlling test acts at
    level: ClassVar[str] = "administrator"

    def __post_init__(self) -> None:
        self._actor: Actor | None = None

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
        """The test as a live client that armed the axis (once per bench)."""
        if self._actor is None:
            guard = self.manager.motion
            self._actor = Actor("tests", self.level, guard.connect("tests"))
            guard.arm(self._actor, self.axis)
        return self._actor
