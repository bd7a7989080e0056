"""REST read latency of the communication server: idle, with 10 clients, and while 10 backup jobs run.

A real ``servostudio serve`` (its simulated drives in its own process, as ``make run`` starts it) answers
``GET /api/buses/sim/nodes/1/objects/statusword``; every figure is the latency a client sees, measured in this run:

- **1 client, idle**: one client reading back to back — the reference of the ratios;
- **10 clients**: ten clients reading at once (one thread and HTTP connection each);
- **1 client, 10 backups**: one client reading while ten backup jobs of every node run (a finished job is
  restarted at once, so ten are always running); interactive reads are served ahead of the jobs' bulk transfers
  (``docs/drive-access.md``), so this stays near the idle figure instead of waiting behind thousands of queued reads;
- **10 clients, 10 backups**: both at once.

    .venv/bin/python bench/rest_latency.py [--reads 200] [--jobs 10]
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import httpx

READ = "/api/buses/sim/nodes/1/objects/statusword"


def free_port() -> int:
    import socket

    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


@contextmanager
def server(projects: Path) -> Iterator[str]:
    """``servostudio serve`` with the simulated drives, ready and scanned; stopped afterwards.  Its fresh data
    directory is set up password-less (single user, localhost), as ``servostudio setup --passwordless`` does."""
    port, data = free_port(), projects.parent / "data"
    servostudio = [sys.executable, "-m", "servostudio"]
    subprocess.run([*servostudio, "setup", "--passwordless", "--data-dir", str(data)], check=True, capture_output=True)
    command = [*servostudio, "serve", "--port", str(port), "--projects", str(projects), "--data-dir", str(data)]
    log = (projects.parent / "server.log").open("wb")
    process = subprocess.Popen(command, stdout=log, stderr=subprocess.STDOUT)
    url = f"http://127.0.0.1:{port}"
    try:
        wait_ready(url, process)
        httpx.post(f"{url}/api/buses/sim/scan", timeout=30).raise_for_status()
        yield url
    finally:
        process.terminate()
        process.wait(timeout=15)
        log.close()


def wait_ready(url: str, process: subprocess.Popen) -> None:
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline:
        if process.poll() is not None:
            raise RuntimeError(f"the server exited with {process.returncode}")
        try:
            if httpx.get(f"{url}/api/health", timeout=1).status_code == 200:
                return
        except httpx.HTTPError:
            time.sleep(0.1)
    raise TimeoutError("the server did not start")


def read_latencies(url: str, reads: int) -> list[float]:
    """One client's latencies (seconds) of ``reads`` reads back to back, on one connection."""
    latencies = []
    with httpx.Client(base_url=url, timeout=60) as client:
        client.get(READ).raise_for_status()  # the connection is open before the clock runs
        for _ in range(reads):
            started = time.perf_counter()
            client.get(READ).raise_for_status()
            latencies.append(time.perf_counter() - started)
    return latencies


def clients(url: str, count: int, reads: int) -> list[float]:
    """Latencies of ``count`` clients reading at once."""
    results: list[list[float]] = [[] for _ in range(count)]

    def run(slot: int) -> None:
        results[slot] = read_latencies(url, reads)

    threads = [threading.Thread(target=run, args=(slot,)) for slot in range(count)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    return [latency for result in results for latency in result]


class BackupLoad:
    """``count`` backup jobs of every node kept running: a finished job is replaced by a new one."""

    def __init__(self, url: str, directory: Path, count: int) -> None:
        self.url, self.directory, self.count = url, directory, count
        self.finished = 0
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)

    def __enter__(self) -> BackupLoad:
        self._thread.start()
        time.sleep(1.0)  # every job is past its start and the nodes' bulk lanes are full
        return self

    def __exit__(self, *_: object) -> None:
        self._stop.set()
        self._thread.join()

    def _run(self) -> None:
        with httpx.Client(base_url=self.url, timeout=60) as client:
            running = [self._start(client, slot) for slot in range(self.count)]
            while not self._stop.is_set():
                for slot, job in enumerate(running):
                    if client.get(f"/api/jobs/{job}").json()["state"] != "running":
                        self.finished += 1
                        running[slot] = self._start(client, slot)
                self._stop.wait(0.2)
            for job in running:
                client.post(f"/api/jobs/{job}/cancel")

    def _start(self, client: httpx.Client, slot: int) -> str:
        answer = client.post("/api/buses/sim/backup", json={"directory": str(self.directory / f"job{slot}")})
        answer.raise_for_status()
        return answer.json()["id"]


def percentile(values: list[float], share: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, round(share * (len(ordered) - 1)))]


def report(rows: list[tuple[str, list[float]]]) -> None:
    idle_p50, idle_p99 = percentile(rows[0][1], 0.5), percentile(rows[0][1], 0.99)
    print("| case | reads | p50 ms | p99 ms | p50 / idle | p99 / idle |")
    print("|---|---|---|---|---|---|")
    for name, latencies in rows:
        p50, p99 = percentile(latencies, 0.5), percentile(latencies, 0.99)
        print(
            f"| {name} | {len(latencies)} | {p50 * 1000:.1f} | {p99 * 1000:.1f} | "
            f"{p50 / idle_p50:.1f} | {p99 / idle_p99:.1f} |"
        )


def measure(url: str, directory: Path, reads: int, jobs: int) -> list[tuple[str, list[float]]]:
    rows = [("1 client, idle", read_latencies(url, reads))]
    rows.append(("10 clients", clients(url, 10, reads // 4)))
    with BackupLoad(url, directory, jobs) as load:
        started = time.monotonic()
        rows.append((f"1 client, {jobs} backups running", read_latencies(url, reads)))
        rows.append((f"10 clients, {jobs} backups running", clients(url, 10, reads // 4)))
        seconds = time.monotonic() - started
    print(f"with {jobs} backups running: {seconds:.1f} s of reads, {load.finished} backup jobs completed meanwhile")
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--reads", type=int, default=200, help="reads per single client (10 clients: a quarter each)")
    parser.add_argument("--jobs", type=int, default=10, help="backup jobs kept running")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as scratch:
        projects = Path(scratch) / "projects"
        projects.mkdir()
        with server(projects) as url:
            load = os.getloadavg()[0]
            rows = measure(url, projects / "backups", args.reads, args.jobs)
    print(f"REST read {READ} — {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, load average {load:.1f}")
    report(rows)


if __name__ == "__main__":
    main()
