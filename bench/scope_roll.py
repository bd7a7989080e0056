"""Live roll mode (docs/scope.md §8): 4 channels × 1 kHz on 3 axes through a real ``servostudio serve``, followed
on the roll's WebSocket as the scope page follows it; figures side by side in one run:

- **samples received / produced**: the samples of every axis the client received against the SYNCs the roll's
  ``seconds`` make (goal 1.0; the server's ``lost`` and its gaps are printed too);
- **latency drive → client**: per batch, from the SYNC of its oldest sample (``synced_at[0]``, the instant the
  drives sampled it, server clock) to its arrival here (same host, same clock): p50, p99 (goal < 100 ms), max;
- **server CPU share**: the server process's CPU time (``/proc``) per wall second while rolling, against the same
  server idle for as long just before (the baseline: its simulated drives run in the same process either way), and
  this client's own share; split by thread (``serve_threads.py``) into the roll's own share (every thread but the
  simulated drives') and the simulated drives' (``sim-clock``), each against its idle figure.

One roll carries the 3 axes (``OBJ@NODE``: one SYNC for all, so the axes are sampled at the same instants). The
channels are the 16-bit status word, current, torque and torque demand (one TPDO per axis: 3,000 frames/s + the
SYNC, 46 % of 1 Mbit/s); the same roll with 32-bit channels would need 86 % and is refused by the budget, which
the bench shows first.

    .venv/bin/python bench/scope_roll.py [--seconds 20]
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import NamedTuple

import httpx
from websockets.sync.client import connect

from rest_latency import free_port, percentile, wait_ready

AXES = (1, 2, 3)
CHANNELS = ("0x6041,0", "0x6078,0", "0x6077,0", "0x6074,0")
WIDE = ("0x6064,0", "0x606C,0", "0x6062,0", "0x60F4,0")
ROLL = "/api/buses/sim/nodes/1/scope/roll"
TICKS = os.sysconf("SC_CLK_TCK")
#: the file in the scratch directory the server writes its threads' CPU times to on SIGUSR1
THREAD_TIMES = "threads.json"
#: the simulated drives' thread (sim/network.py): its time is the simulator's, not the roll's
SIMULATOR = "sim-clock"


@contextmanager
def server(scratch: Path, demo: bool = False, ui: Path | None = None) -> Iterator[tuple[str, int]]:
    """``servostudio serve`` with its simulated drives (password-less, fresh directories; with the shipped demo
    project if asked, serving the UI built in ``ui`` if given): its URL and its pid. It runs in
    ``serve_threads.py``, which tells its threads' CPU times apart (`thread_cpu`)."""
    port, data, projects = free_port(), scratch / "data", scratch / "projects"
    projects.mkdir()
    if demo:
        shutil.copytree(Path(__file__).resolve().parents[1] / "projects" / "demo", projects / "demo")
    servostudio = [sys.executable, "-m", "servostudio"]
    subprocess.run([*servostudio, "setup", "--passwordless", "--data-dir", str(data)], check=True, capture_output=True)
    threads = [sys.executable, str(Path(__file__).with_name("serve_threads.py")), str(scratch / THREAD_TIMES)]
    command = [*threads, "serve", "--port", str(port), "--projects", str(projects), "--data-dir", str(data)]
    command += ["--ui", str(ui)] if ui else []
    with (scratch / "server.log").open("wb") as log:
        process = subprocess.Popen(command, stdout=log, stderr=subprocess.STDOUT)
        url = f"http://127.0.0.1:{port}"
        try:
            wait_ready(url, process)
            httpx.post(f"{url}/api/buses/sim/scan", timeout=30).raise_for_status()
            yield url, process.pid
        finally:
            process.terminate()
            process.wait(timeout=15)


def cpu_seconds(pid: int) -> float:
    """User + system CPU time of a process so far."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / TICKS


def channels(keys: tuple[str, ...]) -> list[str]:
    return [key if node == 1 else f"{key}@{node}" for node in AXES for key in keys]


class CpuMark(NamedTuple):
    """An instant's wall clock and the server's CPU seconds so far: the whole process (ended threads included) and
    each live thread by name."""

    wall: float
    process: float
    threads: dict[str, float]

    @property
    def simulator(self) -> float:
        return self.threads.get(SIMULATOR, 0.0)


def cpu_mark(pid: int, times: Path) -> CpuMark:
    """Now, asked of the server (``serve_threads.py`` writes its threads' times on SIGUSR1)."""
    times.unlink(missing_ok=True)
    os.kill(pid, signal.SIGUSR1)
    deadline = time.monotonic() + 10
    while not times.exists():
        if time.monotonic() > deadline:
            raise RuntimeError("the server did not write its threads' CPU times")
        time.sleep(0.01)
    return CpuMark(time.monotonic(), cpu_seconds(pid), json.loads(times.read_text()))


def shares(pid: int, times: Path, since: CpuMark) -> tuple[float, float]:
    """CPU seconds per wall second since ``since``: the server without its simulated drives, and the drives."""
    now = cpu_mark(pid, times)
    wall, simulator = now.wall - since.wall, now.simulator - since.simulator
    return (now.process - since.process - simulator) / wall, simulator / wall


def by_thread(start: CpuMark, end: CpuMark) -> str:
    """The threads' CPU shares between two marks, the simulated drives' left out, the largest first (``job-…``: the
    roll's job)."""
    wall = end.wall - start.wall
    named = {("roll job" if name.startswith("job-") else name): seconds for name, seconds in end.threads.items()}
    began = {("roll job" if name.startswith("job-") else name): seconds for name, seconds in start.threads.items()}
    found = {name: (seconds - began.get(name, 0.0)) / wall for name, seconds in named.items() if name != SIMULATOR}
    return ", ".join(f"{name} {share * 100:.1f} %" for name, share in sorted(found.items(), key=lambda item: -item[1])
                     if share >= 0.001)  # fmt: skip


def mid_roll(pid: int, times: Path, seconds: float) -> tuple[threading.Thread, list[CpuMark]]:
    """Marks at 10 % and 90 % of the roll, taken meanwhile: the roll's job thread has ended by its end."""
    marks: list[CpuMark] = []

    def take() -> None:
        time.sleep(seconds * 0.1)
        marks.append(cpu_mark(pid, times))
        time.sleep(seconds * 0.8)
        marks.append(cpu_mark(pid, times))

    thread = threading.Thread(target=take, daemon=True)
    thread.start()
    return thread, marks


class Follower:
    """One roll followed on its socket: the samples received and each batch's latency."""

    def __init__(self) -> None:
        self.received = 0
        self.latencies: list[float] = []
        self.numbers_ok = True
        self.end: dict = {}

    def follow(self, url: str, socket_path: str) -> None:
        expected = 0
        with connect(url.replace("http", "ws", 1) + socket_path, max_size=2**24) as socket:
            while True:
                event = json.loads(socket.recv(timeout=30))
                arrived = time.time()
                if event["type"] == "end":
                    self.end = event
                    return
                if event["type"] == "samples":
                    self.numbers_ok &= event["seq"] == expected
                    expected = event["seq"] + event["count"]
                    self.received += event["count"] * len(AXES)
                    self.latencies.append(arrived - event["synced_at"][0])


def measure(url: str, pid: int, seconds: float, times: Path) -> None:
    refused = httpx.post(url + ROLL, json={"channels": channels(WIDE), "period_us": 1000}, timeout=30)
    print(f"32-bit channels, 3 axes: HTTP {refused.status_code}: {refused.json().get('detail')}")
    idle = cpu_mark(pid, times)
    time.sleep(seconds)
    server_idle, simulator_idle = shares(pid, times, idle)
    body = {"channels": channels(CHANNELS), "period_us": 1000, "seconds": seconds}
    started = httpx.post(url + ROLL, json=body, timeout=30)
    started.raise_for_status()
    plan = started.json()["plan"]["stream"]
    follower, mark, own = Follower(), cpu_mark(pid, times), time.process_time()
    marker, marks = mid_roll(pid, times, seconds)
    follower.follow(url, started.json()["socket"])
    marker.join()
    server_rolling, simulator_rolling = shares(pid, times, mark)
    client = (time.process_time() - own) / (time.monotonic() - mark.wall)
    produced = round(seconds * 1000) * len(AXES)
    end = follower.end
    print(f"roll {len(body['channels'])} channels (4 per axis) x 1 kHz on {len(AXES)} axes for {seconds:g} s: "
          f"{plan['frames_per_s']:g} frames/s, bus load {plan['bus_load'] * 100:.0f} % — "
          f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, load average {os.getloadavg()[0]:.1f}")  # fmt: skip
    print("| figure | value | against |")
    print("|---|---|---|")
    print(f"| samples received / produced | {follower.received} / {produced} = {follower.received / produced:.4f} | "
          f"goal 1.0; server: {end.get('lost')} lost, {len(end.get('gaps', []))} gaps, "
          f"in sequence: {follower.numbers_ok} |")  # fmt: skip
    p50, p99 = percentile(follower.latencies, 0.5), percentile(follower.latencies, 0.99)
    worst, batches = max(follower.latencies), len(follower.latencies)
    print(f"| latency drive → client p50 / p99 / max | {p50 * 1e3:.1f} / {p99 * 1e3:.1f} / {worst * 1e3:.1f} ms | "
          f"goal p99 < 100 ms ({batches} batches) |")  # fmt: skip
    rolling, baseline = server_rolling + simulator_rolling, server_idle + simulator_idle
    print(f"| server CPU share rolling / idle | {rolling * 100:.0f} % / {baseline * 100:.0f} % of one core | "
          f"{rolling / baseline:.2f}x idle, the simulated drives included |")  # fmt: skip
    print(f"| — the roll's own share | {server_rolling * 100:.1f} % − {server_idle * 100:.1f} % idle = "
          f"{(server_rolling - server_idle) * 100:.1f} % of one core | every thread but the simulated drives' "
          "(bus reader, roll job, SYNC, WebSockets) |")  # fmt: skip
    print(f"| — by thread, 10 % to 90 % of the roll | {by_thread(*marks)} | `bus sim`: the bus reader, `sync sim`: "
          "the SYNC producer, `MainThread`: the event loop (WebSockets) |")  # fmt: skip
    print(f"| — the simulated drives' share | {simulator_rolling * 100:.1f} % − {simulator_idle * 100:.1f} % idle = "
          f"{(simulator_rolling - simulator_idle) * 100:.1f} % of one core | their thread (`sim-clock`): "
          "answering 3,000 TPDOs/s, in the server's process only because the bench simulates the drives |")  # fmt: skip
    print(f"| client CPU share | {client * 100:.0f} % of one core | the socket's JSON, this process |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=20.0, help="how long to roll (the issue's row: 60)")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as scratch, server(Path(scratch)) as (url, pid):
        measure(url, pid, args.seconds, Path(scratch) / THREAD_TIMES)


if __name__ == "__main__":
    main()
