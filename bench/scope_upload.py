"""Upload of a full oscilloscope recording (4 channels × 2048 samples × 32 bits = 32 KB) against the SDO bus-time
bounds, side by side in one run.

The drive is a simulated XtrapulsPac (with its recorder) in a separate process on the simulator's timed bus
(1 Mbit/s, exact frame lengths with stuff bits, 1 ms drive-side SDO response time), reached over socketcand, as in
``bench/sdo_backup.py``. Rows, each the median of ``--repeats`` runs:

- ours block: the capture service's upload (``services.scope``: 0x5801 by block SDO upload, 127 segments per block,
  with CRC), from its first progress report to its last (the recording counter read after the transfer included);
- ours segmented: the same recording read by the product's SDO engine with a segmented upload (``SdoEngine.upload``);
- canopen segmented / canopen block: the same recording (0x5801) read by the independent ``canopen`` library;
- bounds: the bus time of the frames plus one drive response time per answer the protocol waits for, for one
  segmented upload of the 32 KB (a request per 7 bytes) and for one block upload (127 segments per block).

    .venv/bin/python bench/scope_upload.py [--repeats 3]
"""

from __future__ import annotations

import argparse
import math
import statistics
import subprocess
import sys
import time

import canopen

from servostudio.services.bus import ConnectionManager
from servostudio.services.scope import CaptureDefinition, capture, identity_of
from servostudio.sim.frame import Frame
from servostudio.sim.network import SimulatedNetwork
from servostudio.sim.sdo_server import DEFAULT_RESPONSE_TIME, SERVER_BLOCK_SIZE
from servostudio.sim.socketcand import SocketcandServer
from servostudio.sim.timing import frame_duration

NODE = 1
BITRATE = 1_000_000
FULL = CaptureDefinition(("0x6064,0", "0x606C,0", "0x6062,0", "0x60F4,0"), samples=2048)
BYTES = 2048 * 16


def serve_simulation() -> None:
    """The simulator process: one XtrapulsPac on the timed bus, in real time, behind socketcand."""
    network = SimulatedNetwork(str(NODE), bitrate=BITRATE)
    network.start()
    server = SocketcandServer(network, port=0).start()
    print(server.address[1], flush=True)
    sys.stdin.read()


def frame_time(data: bytes) -> float:
    return frame_duration(Frame(0x580 + NODE, data.ljust(8, b"\0")), BITRATE)


def block_bound(size: int, block: int = SERVER_BLOCK_SIZE) -> float:
    """Initiate, start, blocks of ``block`` segments each acknowledged, end: bus time plus one response time for
    each answer of the drive (a block's segments follow each other without waiting)."""
    segments = math.ceil(size / 7)
    blocks = math.ceil(segments / block)
    frames = 2 + 1 + segments + blocks + 2  # initiate pair, start, segments, acks, end and its answer
    waits = 1 + blocks + 1  # initiate answer, each block, the end
    return frames * frame_time(bytes(8)) + waits * DEFAULT_RESPONSE_TIME


def segmented_bound(size: int) -> float:
    """The initiate pair and one request/answer pair per 7 bytes, each answer one response time after its request
    (bench/sdo_backup.py counts a segmented upload the same way)."""
    pairs = 1 + math.ceil(size / 7)
    return pairs * (2 * frame_time(bytes(8)) + DEFAULT_RESPONSE_TIME)


class Bench:
    def __init__(self) -> None:
        self.process = subprocess.Popen(
            [sys.executable, __file__, "--serve-simulation"], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True
        )
        self.spec = f"socketcand:127.0.0.1:{int(self.process.stdout.readline())}"
        self.manager = ConnectionManager()
        self.connection = self.manager.open(self.spec, wait=5.0)
        self.connection.engine.timeout = 1.0
        self.drive = self.connection.drive(NODE)

    def ours(self) -> float:
        """One full capture; the time from the first part requested to the last received."""
        marks: list[float] = []
        made = capture(self.drive, identity_of(self.connection, self.drive), FULL, lambda event: _mark(event, marks))
        assert made.samples == 2048
        return marks[-1] - marks[0]

    def ours_segmented(self) -> float:
        """The recording the last capture left, read by our engine's segmented upload."""
        started = time.perf_counter()
        data = self.connection.engine.upload(NODE, 0x5801, 0, bulk=True).result(60)
        elapsed = time.perf_counter() - started
        assert len(data) == BYTES, len(data)
        return elapsed

    def canopen(self, block: bool) -> float:
        """The same recording read by the canopen library (on its own client: ours is idle meanwhile)."""
        host, port = self.spec.split(":")[1:]
        network = canopen.Network()
        network.connect(interface="socketcand", host=host, port=int(port), channel="can0")
        try:
            node = network.add_node(NODE, canopen.ObjectDictionary())
            node.sdo.RESPONSE_TIMEOUT = 2.0
            started = time.perf_counter()
            with node.sdo.open(0x5801, 0, "rb", block_transfer=block) as stream:
                data = stream.read()
            elapsed = time.perf_counter() - started
        finally:
            network.disconnect()
        assert len(data) == BYTES, len(data)
        return elapsed

    def close(self) -> None:
        self.manager.close_all()
        self.process.stdin.close()
        self.process.wait(10)


def _mark(event: dict, marks: list[float]) -> None:
    if event.get("stage") == "uploading":
        marks.append(time.perf_counter())


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--serve-simulation", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.serve_simulation:
        serve_simulation()
        return 0
    bench = Bench()
    try:
        ours = statistics.median(bench.ours() for _ in range(args.repeats))
        ours_segmented = statistics.median(bench.ours_segmented() for _ in range(args.repeats))
        segmented = statistics.median(bench.canopen(block=False) for _ in range(args.repeats))
        block = statistics.median(bench.canopen(block=True) for _ in range(args.repeats))
    finally:
        bench.close()
    block_limit, segmented_limit = block_bound(BYTES), segmented_bound(BYTES)
    print(f"full recording: 4 ch x 2048 samples x 32 bit = {BYTES} bytes, 1 Mbit/s, 1 ms SDO response time")
    print(f"{'':28}{'time':>9}{'/ block bound':>15}{'/ segmented bound':>19}")
    rows = [
        ("ours block (capture upload)", ours),
        ("ours segmented", ours_segmented),
        ("canopen segmented", segmented),
        ("canopen block", block),
        ("bound: block SDO", block_limit),
        ("bound: segmented SDO", segmented_limit),
    ]
    for name, seconds in rows:
        print(f"{name:28}{seconds:8.3f}s{seconds / block_limit:14.2f}x{seconds / segmented_limit:18.2f}x")
    print(f"ours block / ours segmented: {ours / ours_segmented:.2f}x; ours block / canopen block: {ours / block:.2f}x")
    return 0


if __name__ == "__main__":
    sys.exit(main())
