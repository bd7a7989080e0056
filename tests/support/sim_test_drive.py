"""The simulator communication tests' drive: a small CiA 402 test dictionary (tests/sim/comms/data/testdrive.eds)
and `CountingBehaviour`, a minimal drive behaviour that stands in for the real drive model (servostudio.sim.drive)
by dependency injection: it counts control periods into 0x6064, raises a fault when control word bit 15 is written
and clears it on bit 7, shows the flash busy flag in status word bit 15, and records the errors the stack raises —
just enough for the stack's behaviour to be observable; and `RawClient`, frame-level access to the simulated bus
in virtual time, with its SDO helpers."""

from __future__ import annotations

import struct
from pathlib import Path

from servostudio.sim.events import DriveEvents
from servostudio.sim.network import SimulatedNetwork
from servostudio.sim.objects import ObjectStore

DATA = Path(__file__).resolve().parents[1] / "sim" / "comms" / "data"  # the test dictionary testdrive.eds


class CountingBehaviour:
    """The minimal drive behaviour (see the module's docstring)."""

    def __init__(self, store: ObjectStore, events: DriveEvents) -> None:
        self.store = store
        self.events = events
        self.syncs = 0
        self.resets = 0
        self.errors: list[int] = []
        store.on_write(0x6040, 0, self._control_word)

    def _control_word(self, index: int, sub: int, value: int) -> None:
        if value & 0x8000:
            self.store.set(0x603F, 0, 0x8611)
            self.events.emergency(0x8611, 35, b"\x01\x02")
        elif value & 0x0080:
            self.store.set(0x603F, 0, 0)
            self.events.emergency_cleared()

    def step(self, dt: float) -> None:
        self.store.set(0x6064, 0, self.store.get(0x6064, 0) + 1)
        busy = 0x8000 if self.events.flash_busy else 0
        self.store.set(0x6041, 0, (self.store.get(0x6041, 0) & 0x7FFF) | busy)

    def on_sync(self) -> None:
        self.syncs += 1

    def on_nmt_reset(self) -> None:
        self.resets += 1

    def raise_error(self, code: int) -> None:
        self.errors.append(code)
        self.events.emergency(0x6320 if code in (42, 43) else 0x8130 if code == 51 else 0x1000, code)


def counting_factory(device: str, node_id: int, store: ObjectStore, events: DriveEvents) -> CountingBehaviour:
    return CountingBehaviour(store, events)


class RawClient:
    """A python-can client on the in-process adapter that steps virtual time itself (deterministic tests)."""

    def __init__(self, network: SimulatedNetwork) -> None:
        self.network = network
        self.bus = network.open_bus()
        self._unclaimed: list = []  # frames seen while waiting for an SDO response, returned by the next collect

    def send(self, can_id: int, data: bytes = b"", rtr: bool = False, dlc: int | None = None) -> None:
        import can

        message = can.Message(
            arbitration_id=can_id,
            data=None if rtr else data,
            is_extended_id=False,
            is_remote_frame=rtr,
            dlc=dlc if dlc is not None else len(data),
        )
        self.bus.send(message)

    def collect(self, seconds: float = 0.01) -> list:
        self.network.advance(seconds)
        messages, self._unclaimed = self._unclaimed, []
        while (message := self.bus.recv(0)) is not None:
            messages.append(message)
        return messages

    def sdo(self, node_id: int, payload: bytes, request_base: int = 0x600, response_base: int = 0x580) -> bytes:
        """One SDO request; returns the data of the single response."""
        self.send(request_base + node_id, payload.ljust(8, b"\0"))
        messages = self.collect(0.01)
        responses = [m for m in messages if m.arbitration_id == response_base + node_id]
        self._unclaimed = [m for m in messages if m.arbitration_id != response_base + node_id]
        assert len(responses) == 1, responses
        return bytes(responses[0].data)

    def close(self) -> None:
        self.bus.shutdown()


def frames_with_id(messages, can_id):
    """The frames of ``messages`` with identifier ``can_id``."""
    return [m for m in messages if m.arbitration_id == can_id]


def write(client, node_id, index, sub, value, size=4):
    """An expedited SDO download of ``value`` (``size`` bytes) by the raw client, which must be confirmed."""
    command = {1: 0x2F, 2: 0x2B, 4: 0x23}[size]
    response = client.sdo(
        node_id, bytes([command]) + struct.pack("<HB", index, sub) + value.to_bytes(size, "little", signed=value < 0)
    )
    assert response[0] == 0x60, response.hex()
