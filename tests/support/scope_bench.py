"""The scope bench: the capture service against simulated drives in this process (the server's ``sim`` bus), the
simulator's own probe (tests/support/recorder_peer.py) as the reference for the recorded values, captures run in the
background while the test acts, and the wait for every node's boot-up."""

from __future__ import annotations

import contextvars
import threading
from collections.abc import Callable
from dataclasses import dataclass, field

from tests.support.recorder_peer import REV, Probe

from servostudio.drive.access import Drive
from servostudio.drive.sdo import SdoNodeRestarted
from servostudio.services.bus import BusConnection
from servostudio.services.cancel import Cancellation
from servostudio.services.scope import Capture, CaptureDefinition, capture, identity_of
from servostudio.sim.network import SimulatedNetwork

WAIT = 10.0


@dataclass
class ScopeBench:
    connection: BusConnection

    @property
    def network(self) -> SimulatedNetwork:
        network = self.connection.simulation
        assert isinstance(network, SimulatedNetwork)
        return network

    def drive(self, node: int = 1) -> Drive:
        """The node as the server hands it out (through the bus's write gate)."""
        return self.connection.drive(node)

    def machine(self, node: int = 1) -> Drive:
        """The node for the test's own set-up writes (the operator moving the axis), past the motion guard."""
        return Drive(self.connection.engine, node, self.connection.library.load("xtrapulspac"))

    def probe(self, keys, node: int = 1) -> Probe:
        with self.network.lock:
            return Probe(self.network.node(node), keys)

    def rows(self, probe: Probe) -> list:
        with self.network.lock:
            return list(probe.rows)

    def enable_profile_velocity(self, node: int = 1) -> None:
        drive = self.machine(node)
        for key, value in (("0x6060", 3), ("0x6083", 100 * REV), ("0x6084", 100 * REV), ("0x60FF", 0)):
            drive.write(key, value)
        for control_word in (0x06, 0x07, 0x0F):
            drive.write("0x6040", control_word)

    def in_background(self, definition: CaptureDefinition, node: int = 1) -> Background:
        """Capture in a thread, following its progress (the test acts while the recorder waits)."""
        return Background(self, definition, node).start()


@dataclass
class Background:
    bench: ScopeBench
    definition: CaptureDefinition
    node: int
    stages: list[dict] = field(default_factory=list)
    result: Capture | Exception | None = None
    cancellation: Cancellation = field(default_factory=Cancellation)
    on_report: Callable[[dict], None] | None = None
    _changed: threading.Condition = field(default_factory=threading.Condition)

    def start(self) -> Background:
        threading.Thread(target=contextvars.copy_context().run, args=(self._run,), daemon=True).start()
        return self

    def _run(self) -> None:
        drive = self.bench.drive(self.node)
        try:
            outcome: Capture | Exception = capture(
                drive, identity_of(self.bench.connection, drive), self.definition, self._report, self.cancellation
            )
        except Exception as error:  # noqa: BLE001 -- the test reads what ended the capture
            outcome = error
        with self._changed:
            self.result = outcome
            self._changed.notify_all()

    def _report(self, event: dict) -> None:
        if self.on_report is not None:
            self.on_report(event)
        with self._changed:
            self.stages.append(event)
            self._changed.notify_all()

    def wait_stage(self, stage: str) -> None:
        with self._changed:
            reached = self._changed.wait_for(
                lambda: any(event["stage"] == stage for event in self.stages) or self.result is not None, WAIT
            )
        assert reached and any(event["stage"] == stage for event in self.stages), (stage, self.stages, self.result)

    def outcome(self, timeout: float = 3 * WAIT) -> Capture | Exception:
        with self._changed:
            assert self._changed.wait_for(lambda: self.result is not None, timeout), self.stages
        assert self.result is not None
        return self.result


def until_booted(drive: Drive) -> None:
    """A loaded host may run a simulated node's boot-up after the bus opened: a request sent before it is lost
    (``SdoNodeRestarted``), so the tests start once every node has answered."""
    for _attempt in range(3):
        try:
            drive.read("0x1000")
            return
        except SdoNodeRestarted:
            continue
    drive.read("0x1000")
