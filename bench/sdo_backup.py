"""SDO throughput and drive backup speed against the bus-time bound, and against a naive canopen loop.

The drives are simulated in a separate process on the simulator's timed bus (1 Mbit/s, exact frame lengths with
stuff bits, 1 ms drive-side SDO response time), reached over its socketcand endpoint — by the communication
server's SDO engine and by a naive canopen loop alike (both on the same socketcand client).  The drive behaviours
are replaced by an idle one: SDO timing does not depend on the motor physics, and without it the simulation keeps
up with real time.  Wall-clock time is what a user waits; "client CPU" is the CPU time of this process only (the
client side), per transfer.

Bounds, from the frames actually exchanged (``servostudio.sim.timing``):
- one drive: every transfer waits for its request frame, the 1 ms response time and its response frame;
- several drives in parallel: the larger of the slowest drive's chain and the total bus occupancy.
A segmented upload counts one such round trip per frame pair.

The host is shared, so each measurement of ours runs `--repeats` times: the tables give the median (and the best)
run; the naive loop, 6–8 times slower, runs once. On a virtual machine the last line gives the share of CPU time
the hypervisor took from this machine during the run ("steal"): the round trips between the two processes need
both to be scheduled, so a few percent of steal shows in the ratios.

    .venv/bin/python bench/sdo_backup.py [--reads 1000] [--drives 8] [--repeats 5]
"""

from __future__ import annotations

import argparse
import math
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import canopen

from servostudio.drive.link import BusLink
from servostudio.drive.sdo import SdoEngine, SdoError
from servostudio.od import builtin_library
from servostudio.od.model import SaveType
from servostudio.services.backup import FileKind, backup_file, backup_objects, run_per_drive
from servostudio.services.bus import BusConnection, EventHub
from servostudio.services.scan import scan
from servostudio.sim.frame import Frame
from servostudio.sim.network import SimulatedNetwork
from servostudio.sim.sdo_server import DEFAULT_RESPONSE_TIME
from servostudio.sim.socketcand import SocketcandServer
from servostudio.sim.timing import frame_duration
from servostudio.transport.socketcand import SocketcandBus
from servostudio.transport.spec import parse_bus_spec

BITRATE = 1_000_000


class IdleBehaviour:
    def step(self, dt: float) -> None:
        pass

    def on_sync(self) -> None:
        pass

    def on_nmt_reset(self) -> None:
        pass


def round_trip_bound(node: int, index: int, sub: int, data: bytes) -> tuple[float, float]:
    """(chain time, bus occupancy) of reading one object whose value is ``data``."""
    request = Frame(0x600 + node, bytes([0x40, index & 0xFF, index >> 8, sub, 0, 0, 0, 0]))
    if len(data) <= 4:
        command = 0x43 | (4 - len(data)) << 2
        pairs = [(request, Frame(0x580 + node, bytes([command, index & 0xFF, index >> 8, sub]) + data.ljust(4, b"\0")))]
    else:
        initiate = bytes([0x41, index & 0xFF, index >> 8, sub]) + len(data).to_bytes(4, "little")
        pairs = [(request, Frame(0x580 + node, initiate))]
        for segment in range(math.ceil(len(data) / 7)):
            chunk = data[segment * 7 : segment * 7 + 7]
            last = segment == math.ceil(len(data) / 7) - 1
            answer = bytes([(segment & 1) << 4 | (7 - len(chunk)) << 1 | last]) + chunk.ljust(7, b"\0")
            ask = bytes([0x60 | (segment & 1) << 4]) + bytes(7)
            pairs.append((Frame(0x600 + node, ask), Frame(0x580 + node, answer)))
    bus = sum(frame_duration(a, BITRATE) + frame_duration(b, BITRATE) for a, b in pairs)
    return bus + len(pairs) * DEFAULT_RESPONSE_TIME, bus


def bound(per_drive: dict[int, list[tuple[int, int, bytes]]]) -> float:
    chains, occupancy = [], 0.0
    for node, objects in per_drive.items():
        chain = 0.0
        for index, sub, data in objects:
            one_chain, one_bus = round_trip_bound(node, index, sub, data)
            chain += one_chain
            occupancy += one_bus
        chains.append(chain)
    return max(max(chains), occupancy)


def cpu_times() -> list[int] | None:
    """The machine's CPU time counters (Linux /proc/stat: user … steal), None elsewhere."""
    try:
        with open("/proc/stat", encoding="ascii") as stat:
            return [int(field) for field in stat.readline().split()[1:9]]
    except (OSError, ValueError):
        return None


def steal_share(before: list[int] | None, after: list[int] | None) -> str:
    if before is None or after is None or sum(after) == sum(before):
        return "not measured"
    return f"{(after[7] - before[7]) / (sum(after) - sum(before)) * 100:.0f} %"


def serve_simulation(drives: int, port: int) -> None:
    """The simulator process: idle drives on the timed bus, run in real time by the product's own loop
    (`SimulatedNetwork.start()`, as in `servostudio sim`), behind socketcand."""
    network = SimulatedNetwork(
        ",".join(str(node) for node in range(1, drives + 1)),
        behaviour_factory=lambda *args: IdleBehaviour(),
        bitrate=BITRATE,
    )
    network.start()
    server = SocketcandServer(network, port=port).start()
    print(server.address[1], flush=True)
    sys.stdin.read()  # until the bench closes the pipe


class Bench:
    def __init__(self, drives: int) -> None:
        self.process = subprocess.Popen(
            [sys.executable, __file__, "--serve-simulation", str(drives)],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
        )
        self.port = int(self.process.stdout.readline())
        self.link = BusLink("bench", self.open_bus)
        self.link.start(wait=5.0)
        self.connection = BusConnection(
            "bench",
            parse_bus_spec(f"socketcand:127.0.0.1:{self.port}"),
            self.link,
            SdoEngine(self.link, 1.0),
            builtin_library(),
            EventHub(),
        )
        scan(self.connection)

    def open_bus(self) -> SocketcandBus:
        return SocketcandBus(channel="can0", host="127.0.0.1", port=self.port)

    def timed(self, work) -> tuple[float, float, object]:
        wall, cpu = time.perf_counter(), time.process_time()
        result = work()
        return time.perf_counter() - wall, time.process_time() - cpu, result

    def close(self) -> None:
        self.link.close()
        self.process.stdin.close()
        self.process.wait(10)


def measure_reads(bench: Bench, count: int, nodes: list[int], repeats: int) -> dict[str, float]:
    engine = bench.connection.engine

    def work():
        futures = [engine.upload(node, 0x6041, 0) for _ in range(count) for node in nodes]
        return [future.result() for future in futures]

    runs = [bench.timed(work) for _ in range(repeats)]
    wall, cpu, values = sorted(runs, key=lambda run: run[0])[len(runs) // 2]
    limit = bound({node: [(0x6041, 0, values[0])] * count for node in nodes})
    total = count * len(nodes)
    return {
        "reads": total,
        "wall": wall,
        "best": min(run[0] for run in runs),
        "cpu_us": cpu / total * 1e6,
        "bound": limit,
        "rate": total / wall,
        "bound_rate": total / limit,
    }


def backup_objects_of(bench: Bench, node: int) -> list[tuple[int, int, bytes]]:
    """(index, sub, value bytes) of the DRIVEPAR objects, read once to size the bound."""
    drive = bench.connection.drive(node)
    variables = backup_objects(drive, SaveType.DRIVEPAR)
    futures = [(var, bench.connection.engine.upload(node, var.index, var.subindex)) for var in variables]
    objects = []
    for var, future in futures:
        try:
            objects.append((var.index, var.subindex, future.result()))
        except SdoError:  # a value the drive refuses to give still costs its transfer: a placeholder of 4 bytes
            objects.append((var.index, var.subindex, b"\0\0\0\0"))
    return objects


def measure_backup(bench: Bench, nodes: list[int], folder: Path, repeats: int) -> dict[str, float]:
    drives = [bench.connection.drive(node) for node in nodes]
    sizes = {node: backup_objects_of(bench, node) for node in nodes}

    def ours():
        results = run_per_drive(
            drives, lambda drive: backup_file(drive, folder / f"node{drive.node}_DRIVEPAR.TXT", FileKind.DRIVEPAR)
        )
        for result in results.values():
            if isinstance(result, Exception):
                raise result

    runs = [bench.timed(ours) for _ in range(repeats)]
    wall, cpu, _ = sorted(runs, key=lambda run: run[0])[len(runs) // 2]
    naive_wall, naive_cpu, _ = bench.timed(lambda: naive_backup(bench, sizes))
    objects = sum(len(objects) for objects in sizes.values())
    return {
        "objects": objects,
        "wall": wall,
        "best": min(run[0] for run in runs),
        "cpu_us": cpu / objects * 1e6,
        "naive_wall": naive_wall,
        "naive_cpu_us": naive_cpu / objects * 1e6,
        "bound": bound(sizes),
    }


def naive_backup(bench: Bench, sizes: dict[int, list[tuple[int, int, bytes]]]) -> None:
    """What a script would do with canopen: one upload after the other, drive after drive."""
    network = canopen.Network(bench.open_bus())
    network.NOTIFIER_CYCLE = 0.05
    network.connect()
    try:
        for node, objects in sizes.items():
            remote = network.add_node(node, canopen.ObjectDictionary())
            remote.sdo.RESPONSE_TIMEOUT = 1.0
            for index, sub, _ in objects:
                remote.sdo.upload(index, sub)
    finally:
        network.disconnect()


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--reads", type=int, default=1000, help="reads per node in the throughput test")
    parser.add_argument("--drives", type=int, default=8)
    parser.add_argument("--repeats", type=int, default=5, help="runs of each measurement of ours (median shown)")
    parser.add_argument("--serve-simulation", type=int, metavar="DRIVES", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.serve_simulation:
        serve_simulation(args.serve_simulation, 0)
        return 0
    bench = Bench(args.drives)
    nodes = list(range(1, args.drives + 1))
    counters = cpu_times()
    try:
        print(
            f"# {time.strftime('%Y-%m-%d %H:%M')} UTC, load average {os.getloadavg()[0]:.1f}, "
            f"{len(bench.connection.nodes)} simulated drives, 1 Mbit/s, 1 ms SDO response time, "
            f"median of {args.repeats} runs (best in brackets)"
        )
        print("\n| SDO reads (0x6041) | reads | wall s | reads/s | bound reads/s | wall / bound | client CPU µs/read |")
        print("|---|---|---|---|---|---|---|")
        for label, chosen in (("1 drive", nodes[:1]), (f"{len(nodes)} drives", nodes)):
            result = measure_reads(bench, args.reads, chosen, args.repeats)
            print(
                f"| {label} | {result['reads']} | {result['wall']:.3f} | {result['rate']:.0f} | "
                f"{result['bound_rate']:.0f} | {result['wall'] / result['bound']:.2f} "
                f"({result['best'] / result['bound']:.2f}) | {result['cpu_us']:.0f} |"
            )
        print(
            "\n| DRIVEPAR.TXT backup | objects | bound s | ours s | ours / bound | naive canopen s | naive / ours | "
            "client CPU µs/object ours / naive |"
        )
        print("|---|---|---|---|---|---|---|---|")
        with tempfile.TemporaryDirectory() as folder:
            for label, chosen in (("1 drive", nodes[:1]), (f"{len(nodes)} drives", nodes)):
                result = measure_backup(bench, chosen, Path(folder), args.repeats)
                print(
                    f"| {label} | {result['objects']} | {result['bound']:.3f} | {result['wall']:.3f} | "
                    f"{result['wall'] / result['bound']:.2f} ({result['best'] / result['bound']:.2f}) | "
                    f"{result['naive_wall']:.3f} | {result['naive_wall'] / result['wall']:.1f} | "
                    f"{result['cpu_us']:.0f} / {result['naive_cpu_us']:.0f} |"
                )
        print(f"\nCPU time taken by the hypervisor during the run (steal): {steal_share(counters, cpu_times())}")
    finally:
        bench.close()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
