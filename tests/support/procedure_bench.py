"""The procedure bench: simulated drives in this process on hidden seeded plants, their virtual time run faster than
the wall clock by a thread of the test's own, with the procedure service acting as an armed controller; and the
commissioning a user does on it (datasheet → current loop → auto-phasing → auto-tuning).  Shared by the procedure,
frequency-response and report tests."""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass, field

from servostudio.drive.access import Drive
from servostudio.services.audit import Actor, acting_as
from servostudio.services.bus import BusConnection, ConnectionManager
from servostudio.services.cancel import Cancellation
from servostudio.services.procedures import ProcedureRequest, ProcedureService
from servostudio.sim.network import SimulatedNetwork, drive_behaviour_factory
from servostudio.sim.plant import Plant

SDO_TIMEOUT = 1.0


class FastClock:
    """Runs a network's virtual time at up to ``speed`` × the wall clock (as fast as the host allows when larger)."""

    def __init__(self, network: SimulatedNetwork, speed: float) -> None:
        self.network, self.speed = network, speed
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="fast-clock", daemon=True)

    def start(self) -> FastClock:
        self._thread.start()
        return self

    def stop(self) -> None:
        self._stop.set()
        self._thread.join()

    def pace(self, speed: float) -> None:
        self._origin = (time.monotonic(), self.network.now)
        self.speed = speed

    def _run(self) -> None:
        self._origin = (time.monotonic(), self.network.now)
        while not self._stop.is_set():
            origin_wall, origin_virtual = self._origin
            allowed = origin_virtual + (time.monotonic() - origin_wall) * self.speed
            if self.network.now < allowed:
                self.network.advance(min(0.001, allowed - self.network.now))
            else:
                time.sleep(0.0005)


class _Network:
    """What the connection manager keeps of a simulation it did not start itself."""

    def __init__(self, clock: FastClock) -> None:
        self.clock = clock

    def stop(self) -> None:
        self.clock.stop()


@dataclass
class Bench:
    connection: BusConnection
    network: SimulatedNetwork
    manager: ConnectionManager
    clock: FastClock | None = None
    service: ProcedureService = field(default_factory=ProcedureService)
    _actor: Actor | None = None

    def pace(self, speed: float) -> None:
        """Run virtual time at ``speed`` × the wall clock from now on (the commutation check's torque pulses end
        after a bus round trip: at a high speed that is a long pulse)."""
        assert self.clock is not None
        self.clock.pace(speed)

    @property
    def axis(self) -> tuple[str, int]:
        return (self.connection.id, 1)

    def drive(self, node: int = 1) -> Drive:
        """The node as the server hands it out (through the bus's write gate)."""
        return self.connection.drive(node)

    def machine(self, node: int = 1) -> Drive:
        """The node for the test's own set-up (the person at the terminal), past the motion guard."""
        return Drive(self.connection.engine, node, self.connection.library.load(self.drive(node).profile.device))

    def plant(self, node: int = 1) -> Plant:
        """The hidden truth (the service never sees it)."""
        with self.network.lock:
            return self.network.node(node).behaviour.plant  # type: ignore[attr-defined]

    def controller(self) -> Actor:
        """The live client that armed the axis (what a browser tab or the CLI is), one per bench."""
        if self._actor is None:
            guard = self.manager.motion
            self._actor = Actor("tests", "administrator", guard.connect("tests"))
            guard.arm(self._actor, self.axis)
        return self._actor

    def run(self, name: str, request: ProcedureRequest | None = None, actor: Actor | None = None,
            cancellation: Cancellation | None = None, events: list | None = None) -> dict:  # fmt: skip
        """The procedure as a job runs it, acting as ``actor`` (an armed controller unless given)."""
        with acting_as(actor or self.controller()):
            return self.service.run(
                self.manager.motion, self.axis, self.drive(), name, request or ProcedureRequest(),
                (events.append if events is not None else lambda event: None), cancellation or Cancellation(),
            )  # fmt: skip


def open_bench(nodes: str, seed: int | None, speed: float) -> Bench:
    factory = drive_behaviour_factory(seed=seed) if seed is not None else None
    network = SimulatedNetwork(nodes, behaviour_factory=factory)
    clock = FastClock(network, speed)
    manager = ConnectionManager()
    manager._opener = lambda spec: ((lambda: network.open_bus()), _Network(clock))  # type: ignore[method-assign]
    connection = manager.open("sim", wait=5.0)
    clock.start()
    assert connection.link.wait_connected(5.0)
    connection.engine.timeout = SDO_TIMEOUT
    return Bench(connection, network, manager, clock)


def datasheet(bench, plant: Plant) -> None:
    """What a user types in from the motor's datasheet (motor data 0x6410), and manual brake control (no brake)."""
    machine = bench.machine()
    for key, value in (
        ("0x6410,7", plant.max_speed_rpm),
        ("0x6410,9", round(plant.stall_current * 1000)),
        ("0x6410,10", round(plant.peak_current * 1000)),
        ("0x6410,11", round(plant.torque_constant * 1000)),
        ("0x6410,12", round(plant.motor_inertia * 1e6)),
        ("0x60FE,2", 1),
        ("0x60FE,1", 0),
    ):
        machine.write(key, value)


def commission(bench, bandwidth: int = 75, tuning_filter: str = "standard") -> tuple[Plant, dict, dict, dict]:
    plant = bench.plant()
    datasheet(bench, plant)
    inductance = round(plant.inductance * 1e4) / 10  # mH, as the datasheet gives it
    current = bench.run("current_loop", ProcedureRequest({"inductance_mh": inductance}))
    bench.pace(2.0)  # the commutation check's pulses end after a bus round trip
    phasing = bench.run("auto_phasing")
    bench.pace(5.0)
    options = {"bandwidth": bandwidth, "filter": tuning_filter, "mode": "min-overshoot"}
    return plant, current, phasing, bench.run("auto_tuning", ProcedureRequest(options))
