"""Real-time factor of the simulated drives (simulated seconds per wall second), 1 and 8 axes.

Two levels are measured:
- "drive engine": the drive behaviours alone (state machine, modes, loops, physics), stepped every 250 µs;
- "network": complete simulated CANopen nodes in a `SimulatedNetwork` (NMT, PDO polling, timers, clock queue).
Every axis moves (profile velocity, reversing every 0.5 s) so the loops and the physics do real work.
A factor above 1 means the simulation runs faster than real time on one core. The wall-clock factor depends on
what else the host runs; the CPU factor counts only the time this process got.

    .venv/bin/python bench/sim_realtime.py [--seconds 2]
"""

from __future__ import annotations

import argparse
import os
import time
from collections.abc import Callable

from servostudio.od import builtin_library
from servostudio.sim.clock import CONTROL_PERIOD
from servostudio.sim.drive import make_behaviour
from servostudio.sim.network import SimulatedNetwork
from servostudio.sim.objects import ObjectStore
from servostudio.sim.plant import Plant

REV = 4096


class NoEvents:
    """No CAN stack behind the engine-only measurement."""

    flash_busy = False

    def emergency(self, error_code: int, infranor_code: int = 0, manufacturer: bytes = b"") -> None:
        raise RuntimeError(f"unexpected drive error 0x{error_code:04X} during the benchmark")

    def emergency_cleared(self) -> None:
        pass


def start_motion(store: ObjectStore) -> None:
    """Enable in profile velocity and give a target (the same bus writes a master would make)."""
    write = store.write_from_bus
    write(0x6060, 0, 3)
    write(0x6083, 0, REV * 100)
    write(0x6084, 0, REV * 100)
    write(0x6040, 0, 0x06)


def set_target(store: ObjectStore, velocity: int) -> None:
    store.write_from_bus(0x60FF, 0, velocity)


def enable(store: ObjectStore, control_word: int) -> None:
    store.write_from_bus(0x6040, 0, control_word)


def measure(
    axes: int, seconds: float, build: Callable[[int], tuple[list[ObjectStore], Callable[[float], None]]]
) -> tuple[float, float]:
    stores, advance = build(axes)
    for store in stores:
        start_motion(store)
    advance(0.002)
    for store in stores:
        enable(store, 0x07)
    advance(0.002)
    for store in stores:
        enable(store, 0x0F)
    advance(0.01)
    wall_start, cpu_start = time.perf_counter(), time.process_time()
    elapsed = 0.0
    direction = 1
    while elapsed < seconds:
        for store in stores:
            set_target(store, direction * REV * 20)
        advance(0.5)
        elapsed += 0.5
        direction = -direction
    return time.perf_counter() - wall_start, time.process_time() - cpu_start


def engine(axes: int) -> tuple[list[ObjectStore], Callable[[float], None]]:
    od = builtin_library().load("xtrapulspac")
    stores = [ObjectStore(od, node) for node in range(1, axes + 1)]
    drives = [make_behaviour("xtrapulspac", store, Plant.commissioned(), NoEvents(), True) for store in stores]

    def advance(seconds: float) -> None:
        for _ in range(round(seconds / CONTROL_PERIOD)):
            for drive in drives:
                drive.step(CONTROL_PERIOD)

    return stores, advance


def network(axes: int) -> tuple[list[ObjectStore], Callable[[float], None]]:
    net = SimulatedNetwork(",".join(str(n) for n in range(1, axes + 1)))
    net.advance(0.01)
    return [node.store for node in net.nodes.values()], net.advance


def call_cost_ns() -> float:
    """Cost of one empty Python function call on this host (to compare hosts; ~50 ns on an idle desktop core)."""

    def nothing(value: int) -> int:
        return value

    start = time.process_time()
    for value in range(200_000):
        nothing(value)
    return (time.process_time() - start) / 200_000 * 1e9


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=2.0, help="simulated seconds per measurement")
    args = parser.parse_args()
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(
        f"control period {CONTROL_PERIOD * 1e6:.0f} µs, {args.seconds:g} s simulated, load average {load:.1f}, "
        f"{os.cpu_count()} CPUs, Python call {call_cost_ns():.0f} ns"
    )
    print(
        f"| {'level':<13} | axes | wall s | CPU s | real-time factor (wall) | real-time factor (CPU) "
        f"| µs CPU per axis-period |"
    )
    print(
        f"|{'-' * 15}|------|--------|-------|-------------------------|------------------------"
        f"|------------------------|"
    )
    for name, build in (("drive engine", engine), ("network", network)):
        for axes in (1, 8):
            wall, cpu = measure(axes, args.seconds, build)
            per_period = cpu / (args.seconds / CONTROL_PERIOD) / axes * 1e6
            print(
                f"| {name:<13} | {axes:>4} | {wall:6.2f} | {cpu:5.2f} | {args.seconds / wall:23.2f} "
                f"| {args.seconds / cpu:22.2f} | {per_period:22.1f} |"
            )


if __name__ == "__main__":
    main()
