"""The drive-behaviour harness: a real ObjectStore on the built-in dictionary, the simulated drive's behaviour
(servostudio.sim.drive), and a recorder in place of the node's DriveEvents, stepped by the test (integration over
CAN is tested in tests/sim/comms)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from servostudio.od import builtin_library
from servostudio.sim.clock import CONTROL_PERIOD
from servostudio.sim.drive import make_behaviour
from servostudio.sim.objects import ObjectStore
from servostudio.sim.plant import Plant

NODE_ID = 5


@dataclass
class EventRecorder:
    """Stands in for servostudio.sim.events.DriveEvents: records what the drive reports."""

    emergencies: list[tuple[int, int, bytes]] = field(default_factory=list)
    cleared: int = 0
    flash_busy: bool = False
    nmt_state: str = "OPERATIONAL"

    def emergency(self, error_code: int, infranor_code: int = 0, manufacturer: bytes = b"") -> None:
        self.emergencies.append((error_code, infranor_code, manufacturer))

    def emergency_cleared(self) -> None:
        self.cleared += 1


class Harness:
    """One simulated drive's behaviour on its object store, stepped in control periods by the test."""

    def __init__(self, device: str, plant: Plant, commissioned: bool) -> None:
        self.store = ObjectStore(builtin_library().load(device), NODE_ID)
        self.events = EventRecorder()
        self.plant = plant
        self.drive = make_behaviour(device, self.store, plant, self.events, commissioned)

    def write(self, index: int, sub: int, value: Any) -> None:
        """A bus write (SDO/RPDO path: range check and hooks)."""
        self.store.write_from_bus(index, sub, value)

    def read(self, index: int, sub: int = 0) -> Any:
        return self.store.read_from_bus(index, sub)

    def run(self, seconds: float) -> None:
        for _ in range(round(seconds / CONTROL_PERIOD)):
            self.drive.step(CONTROL_PERIOD)

    def run_until(self, condition, timeout: float, step: float = 0.005) -> float:
        """Run until `condition()` holds; returns the simulated time it took (fails the test on timeout)."""
        elapsed = 0.0
        while not condition():
            if elapsed >= timeout:
                raise AssertionError(f"condition not reached within {timeout} s of simulated time")
            self.run(step)
            elapsed += step
        return elapsed

    @property
    def status(self) -> int:
        return int(self.read(0x6041))

    def control(self, word: int, settle: float = 0.002) -> None:
        self.write(0x6040, 0, word)
        self.run(settle)

    def enable(self, mode: int | None = None) -> None:
        if mode is not None:
            self.write(0x6060, 0, mode)
        self.control(0x06)
        self.control(0x07)
        self.control(0x0F, settle=0.01)
        assert self.status & 0x6F == 0x27, hex(self.status)
