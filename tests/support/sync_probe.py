"""The SYNC probe: at every SYNC a simulated drive receives, the virtual time and the values its TPDO is built
from (noted on the simulator's thread), and what the TPDO capture tests compare with it: where captured rows sit
among the probe's, an axis set moving in profile velocity, the TPDO configuration a capture must put back."""

from __future__ import annotations

from servostudio.drive.access import Drive

POSITION, VELOCITY, STATUS_WORD = (0x6064, 0), (0x606C, 0), (0x6041, 0)
TPDO_OBJECTS = [(0x1800 + n, sub) for n in range(3) for sub in (1, 2)] + [
    (0x1A00 + n, sub) for n in range(3) for sub in range(9)
]


class SyncProbe:
    """Every SYNC node ``node`` receives: (virtual time, values of ``keys`` then), on the simulator's thread."""

    def __init__(self, network, node: int, keys) -> None:
        self.rows: list[tuple[float, tuple]] = []
        self.network = network
        with network.lock:
            simulated = network.node(node)
            store, engine = simulated.store, simulated.pdo
            variables = [store.od[key] for key in keys]
            original = engine.on_sync

            def on_sync() -> None:
                self.rows.append((simulated.clock.now, tuple(store.read_value(v) for v in variables)))
                original()

            engine.on_sync = on_sync

    def values(self) -> list[tuple]:
        with self.network.lock:
            return [values for _, values in self.rows]

    def times(self) -> list[float]:
        with self.network.lock:
            return [when for when, _ in self.rows]


def offset_of(rows: list[tuple], captured: list[tuple]) -> int:
    """Where the captured samples sit in the probe's rows (they must be a run of consecutive SYNCs)."""
    matches = [j for j in range(len(rows) - len(captured) + 1) if rows[j : j + len(captured)] == captured]
    assert matches, f"the captured samples are not the simulator's values at consecutive SYNCs: {captured[:3]}…"
    return matches[0]


def moving(bench, node: int, device: str, speed: int) -> None:
    """The axis in profile velocity at ``speed`` (the test's own writes, past the motion guard)."""
    drive = Drive(bench.connection.engine, node, bench.connection.library.load(device))
    for key, value in (("0x6060", 3), ("0x6083", 400_000), ("0x6084", 400_000), ("0x60FF", speed)):
        drive.write(key, value)
    for control_word in (0x06, 0x07, 0x0F):
        drive.write("0x6040", control_word)


def tpdo_configuration(drive: Drive) -> dict:
    present = [key for key in TPDO_OBJECTS if drive.dictionary.get(*key) is not None]
    return {key: drive.read(key).raw for key in present}


def rows_of(made) -> list[tuple]:
    return list(zip(*made.columns, strict=True))
