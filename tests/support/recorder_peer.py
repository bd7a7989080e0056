"""The oscilloscope recorder seen from outside: a `canopen` peer of simulated XtrapulsPacs over socketcand, and a
probe that reads the simulator's own values after every control period.

The peer configures, arms and uploads through SDO only, and decodes the buffer itself (from the channel data
types 0x5810 and `od.decode`), as the tool will. The probe is the reference: it runs on the simulator's thread
right after each control period and reads each object the way any bus read does (`ObjectStore.read_value`), so
a recorded value must equal the probe's value of the same period. It also notes the virtual time of chosen
writes (the arm command, a set-point), which fixes the instants the recorder must sample: the first control
period after the arm, then every `multiplier` periods (docs/scope.md).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import canopen

from servostudio.od.datatypes import DataType, decode
from servostudio.od.library import BUILTIN_EDS_DIR
from servostudio.sim.clock import CONTROL_PERIOD
from servostudio.sim.network import SimulatedNetwork
from servostudio.sim.node import SimulatedNode
from servostudio.sim.socketcand import SocketcandServer

XTRAPULSPAC_EDS = str(Path(BUILTIN_EDS_DIR) / "xtrapulspac.eds")
WAIT = 10.0  # s of wall clock for any wait (the host may be loaded; virtual time then slips)
REV = 4096  # user units per revolution (0x6093 at its default)

IDLE, FILLING, WAITING, RECORDING, DONE = range(5)
STOP, ARM, FORCE = range(3)
IMMEDIATE, EDGE = 0, 1
SINGLE, NORMAL, AUTO = 0, 1, 2
RISING, FALLING, EITHER = 0, 1, 2

Key = tuple[int, int]
POSITION, VELOCITY, CURRENT, STATUS_WORD = (0x6064, 0), (0x606C, 0), (0x6078, 0), (0x6041, 0)
TARGET_VELOCITY = (0x60FF, 0)
RECORDER_STATUS, RECORDING_COUNTER = (0x5829, 0), (0x5804, 6)


def pointer(key: Key, data_type: DataType) -> int:
    """A source pointer: index << 16 | sub << 8 | size in bits."""
    return key[0] << 16 | key[1] << 8 | (data_type.fixed_size * 8)


@dataclass(frozen=True)
class Row:
    """The probe's values after one control period."""

    time: float
    values: tuple

    @property
    def period(self) -> int:
        return round(self.time / CONTROL_PERIOD)


class Probe:
    """Values of `keys` after every control period of one simulated node, and the times of watched writes."""

    def __init__(self, node: SimulatedNode, keys: Sequence[Key]) -> None:
        self.keys = list(keys)
        self.rows: list[Row] = []
        self.writes: dict[Key, list[tuple[float, object]]] = {}
        self._node = node
        variables = [node.store.od[key] for key in keys]
        read, clock, step = node.store.read_value, node.clock, node.step

        def probed_step(dt: float) -> None:
            step(dt)
            self.rows.append(Row(clock.now, tuple(read(var) for var in variables)))

        node.step = probed_step

    def watch(self, key: Key) -> None:
        """Note each accepted bus write of `key` (the hook runs after the recorder's, which may refuse it)."""
        times = self.writes.setdefault(key, [])
        self._node.store.on_write(*key, lambda index, sub, value: times.append((self._node.clock.now, value)))

    def column(self, key: Key, rows: Sequence[Row]) -> list:
        position = self.keys.index(key)
        return [row.values[position] for row in rows]

    def values(self, rows: Sequence[Row], keys: Sequence[Key]) -> list[tuple]:
        positions = [self.keys.index(key) for key in keys]
        return [tuple(row.values[position] for position in positions) for row in rows]


def sample_grid(rows: Sequence[Row], after: float, multiplier: int) -> list[Row]:
    """The rows at the recorder's sample instants for an arm at `after`: the first control period after it, then
    every `multiplier` periods."""
    first = next(number for number, row in enumerate(rows) if row.time > after)
    return list(rows[first::multiplier])


def last_write(probe: Probe, key: Key, value: object | None = None) -> float:
    """When `key` was last written (with `value`, if given)."""
    return [when for when, written in probe.writes[key] if value is None or written == value][-1]


@dataclass(frozen=True)
class Recording:
    raw: bytes
    records: list[tuple]
    trigger: int


class ScopePeer:
    """One drive's recorder through canopen SDO."""

    def __init__(self, node: canopen.RemoteNode) -> None:
        self.node = node

    def write(self, index: int, sub: int, value: int | str) -> None:
        """SDO download, encoded by canopen from the EDS (the peer's own reading of the dictionary)."""
        self.node.sdo.download(index, sub, self._entry(index, sub).encode_raw(value))

    def read(self, index: int, sub: int = 0) -> int:
        return self._entry(index, sub).decode_raw(self.node.sdo.upload(index, sub))

    def _entry(self, index: int, sub: int):
        return self.node.object_dictionary.get_variable(index, sub)

    def configure(
        self,
        channels: Sequence[int],
        depth: int,
        multiplier: int = 1,
        pre_trigger: int = 0,
        mode: int = IMMEDIATE,
        source: int = 1,
        level: int = 0,
        edge: int = RISING,
        rearm: int = SINGLE,
        timeout_ms: int = 100,
    ) -> None:
        """Every configuration object, channels beyond `channels` off."""
        for channel, source_pointer in enumerate([*channels, 0, 0, 0, 0][:4], start=1):
            self.write(0x5811, channel, source_pointer)
        for (index, sub), value in {
            (0x5804, 2): depth,
            (0x5804, 4): multiplier,
            (0x5805, 0): pre_trigger,
            (0x5820, 1): source,
            (0x5820, 2): mode,
            (0x5820, 3): rearm,
            (0x5820, 4): timeout_ms,
            (0x5822, 1): level,
            (0x5822, 2): edge,
        }.items():
            self.write(index, sub, value)

    def command(self, command: int) -> None:
        self.write(0x5828, 0, command)

    def status(self) -> int:
        return self.read(0x5829)

    def wait_status(self, wanted: int, timeout: float = WAIT) -> None:
        self.wait(lambda: self.status() == wanted, f"recorder status {wanted}", timeout)

    def wait(self, condition: Callable[[], bool], what: str, timeout: float = WAIT) -> None:
        deadline = time.monotonic() + timeout
        while not condition():
            if time.monotonic() > deadline:
                raise AssertionError(f"{what} not reached within {timeout} s (status {self.status()})")
            time.sleep(0.01)

    def upload(self, index: int = 0x5801, block: bool = True) -> bytes:
        if not block:
            return self.node.sdo.upload(index, 0)
        with self.node.sdo.open(index, 0, "rb", block_transfer=True) as stream:
            return stream.read()

    def channel_types(self) -> list[DataType]:
        codes = [self.read(0x5810, channel) for channel in (1, 2, 3, 4)]
        return [DataType(code) for code in codes if code]

    def recording(self, block: bool = True) -> Recording:
        raw = self.upload(block=block)
        return Recording(raw, decode_records(raw, self.channel_types()), self.read(0x5840, 3))


def decode_records(raw: bytes, types: Sequence[DataType]) -> list[tuple]:
    """The peer's own parser: channel values in order, each `od.decode`d from its CiA 301 bytes."""
    sizes = [data_type.fixed_size for data_type in types]
    record_size = sum(sizes)
    assert len(raw) % record_size == 0, f"{len(raw)} bytes is not a whole number of {record_size}-byte records"
    records = []
    for start in range(0, len(raw), record_size):
        offset, values = start, []
        for data_type, size in zip(types, sizes, strict=True):
            values.append(decode(data_type, raw[offset : offset + size]))
            offset += size
        records.append(tuple(values))
    return records


@dataclass
class ScopeBus:
    network: SimulatedNetwork
    client: canopen.Network
    host: str
    port: int

    def peer(self, node_id: int = 1) -> ScopePeer:
        node = canopen.RemoteNode(node_id, XTRAPULSPAC_EDS)
        node.sdo.RESPONSE_TIMEOUT = 5.0
        self.client.add_node(node)
        return ScopePeer(node)

    def probe(self, keys: Sequence[Key], node_id: int = 1) -> Probe:
        with self.network.lock:
            return Probe(self.network.node(node_id), keys)

    def rows(self, probe: Probe) -> list[Row]:
        """A consistent copy of the probe's rows (the simulator's thread appends to them)."""
        with self.network.lock:
            return list(probe.rows)


@contextmanager
def scope_bus(nodes: str = "1") -> Iterator[ScopeBus]:
    """Commissioned XtrapulsPacs in real time behind socketcand, and a canopen client connected to them."""
    network = SimulatedNetwork(nodes)
    network.start()
    server = SocketcandServer(network, port=0).start()
    client = canopen.Network()
    client.NOTIFIER_CYCLE = 0.1  # the reader thread notices disconnect() within 0.1 s instead of 1 s
    host, port = server.address
    try:
        client.connect(interface="socketcand", host=host, port=port, channel="can0")
        yield ScopeBus(network, client, host, port)
    finally:
        if client.bus is not None:
            client.disconnect()
        server.stop()
        network.stop()
