"""Restore of one DRIVEPAR.TXT by every path a user has, on the same bus in one run (issue #14 point 5).

Set-up: ``servostudio sim`` (three XtrapulsPac drives, 1 ms SDO response time, in real time) in a process of its
own with its socketcand endpoint and its RS-232 link; ``servostudio serve --bus socketcand:…`` in another, as a
user runs them.  The file is node 1's own DRIVEPAR.TXT (≈ 370 objects), backed up through the server first.  Each
path restores it to node 1 (validated, written, read back, stored to flash with 'save'), ``--repeats`` times,
the paths interleaved so they see the same machine load; the table gives the median (best in brackets) of the wall
time a user waits and of the restore's own seconds (its result's ``seconds``), and the restore time per object
against the headless CLI's (docs/benchmarks.md):

- **CLI, own bus**: ``servostudio restore --bus socketcand:… --node 1 --in DRIVEPAR.TXT`` (the reference; the
  process start is in the figure, as a user waits for it);
- **CLI over RS-232**: the same over the simulator's serial link (``serial:socket://…@115200``);
- **CLI through the server**: ``servostudio restore --server URL --node 1 --in DRIVEPAR.TXT``;
- **REST/UI file job**: ``PUT …/files/DRIVEPAR.TXT?job=true`` until the job ended ("Restore from PC…");
- **UI "Restore project to drive"**: what it does now: the project's values spelt as the drive's files, each restored
  by one file job (the project holds node 1's DRIVEPAR.TXT and USER_PAR.TXT values, read from the drive first);
- **UI before**: what "Restore project to drive" did until issue #14: one ``PUT …/objects/KEY`` per value, one
  after the other (no read-back, no store — so it did less work and was still the slowest).

    .venv/bin/python bench/restore_paths.py [--repeats 5]
"""

from __future__ import annotations

import argparse
import json
import os
import socket
import statistics
import struct
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

import httpx

SERVOSTUDIO = [sys.executable, "-m", "servostudio"]
NODE = 1


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


@contextmanager
def process(command: list[str], log: Path) -> Iterator[subprocess.Popen]:
    with log.open("wb") as output:
        child = subprocess.Popen(command, stdout=output, stderr=subprocess.STDOUT)
        try:
            yield child
        finally:
            child.terminate()
            child.wait(timeout=15)


def wait_for(check: Callable[[], bool], what: str, log: Path, timeout: float = 120.0) -> None:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        try:
            if check():
                return
        except (httpx.HTTPError, OSError):
            pass
        time.sleep(0.1)
    raise TimeoutError(f"{what} did not start:\n{log.read_text(errors='replace')}")


def _listening(port: int) -> bool:
    with socket.create_connection(("127.0.0.1", port), timeout=1):
        return True


def wait_job(client: httpx.Client, job: dict) -> dict:
    while job["state"] == "running":
        time.sleep(0.01)
        job = client.get(f"/api/jobs/{job['id']}").json()
    if job["state"] != "done":
        raise RuntimeError(f"job {job['id']} ended {job['state']}: {job['error']}")
    return job


Timing = tuple[float, float, int]
"""(wall seconds the user waits, seconds of the restore itself as its result reports them, objects written)."""


class Paths:
    """Every restore path, each a function that restores once and returns its `Timing`."""

    def __init__(self, file: Path, client: httpx.Client, axis: str) -> None:
        self.file, self.client, self.axis = file, client, axis
        self.text = file.read_text(encoding="latin-1")
        self.objects = len(_lines(self.text))

    def cli(self, *target: str) -> Timing:
        command = [*SERVOSTUDIO, "restore", *target, "--node", str(NODE), "--in", str(self.file)]
        started = time.perf_counter()
        done = subprocess.run(command, capture_output=True, text=True, env={**os.environ, "SERVOSTUDIO_SERVER": ""})
        wall = time.perf_counter() - started
        if done.returncode != 0 or not json.loads(done.stdout)["ok"]:
            raise RuntimeError(f"{' '.join(target)}: exit {done.returncode}: {done.stderr}")
        return wall, json.loads(done.stdout)["seconds"], self.objects

    def file_job(self) -> Timing:
        started = time.perf_counter()
        seconds = self._restore("DRIVEPAR.TXT", self.text)
        return time.perf_counter() - started, seconds, self.objects

    def project_job(self) -> Timing:
        """What "Restore project to drive" does now: the project's values spelt as the drive's files
        (``frontend/src/lib/objectfile.ts``), each restored by one file job."""
        started = time.perf_counter()
        rows = self.client.get(f"/api/projects/bench/axes/{self.axis}/parameters").json()["parameters"]
        files = project_files(rows)
        seconds = sum(self._restore(name, text) for name, text in files.items())
        return time.perf_counter() - started, seconds, sum(len(_lines(text)) for text in files.values())

    def object_writes(self) -> Timing:
        started = time.perf_counter()
        for line in _lines(self.text):
            key, _, value = line.partition("=")
            answer = self.client.put(f"/api/buses/socketcand/nodes/{NODE}/objects/{key}", json={"value": value})
            answer.raise_for_status()
        wall = time.perf_counter() - started
        return wall, wall, self.objects

    def _restore(self, name: str, text: str) -> float:
        """One file job (as "Restore from PC…" starts it); the restore's own seconds."""
        job = self.client.put(
            f"/api/buses/socketcand/nodes/{NODE}/files/{name}?job=true",
            content=text.encode("latin-1"),
            headers={"Content-Type": "text/plain"},
        ).json()
        return float(wait_job(self.client, job)["result"][str(NODE)][0]["seconds"])


def _lines(text: str) -> list[str]:
    return [line for line in text.splitlines() if line and not line.startswith(";")]


def project_files(rows: list[dict]) -> dict[str, str]:
    """The object files of the values the project sets, spelt as the browser spells them
    (``frontend/src/lib/objectfile.ts``): REAL values as their IEEE-754 bits, texts the syntax cannot carry left out."""
    files: dict[str, list[str]] = {}
    for row in rows:
        value, kind = row["value"], row["data_type"].upper()
        if row["file"] is None or value is None:
            continue
        if kind in ("REAL32", "REAL64"):
            fmt = "<f" if kind == "REAL32" else "<d"
            value = int.from_bytes(struct.pack(fmt, value), "little")
        elif isinstance(value, str) and _unwritable(value):
            continue
        files.setdefault(row["file"], []).append(f"0x{row['index']:04X},{row['subindex']}={value}")
    return {name: "\n".join(lines) + "\n" for name, lines in files.items()}


def _unwritable(text: str) -> bool:
    return not text or text != text.strip() or text[0] in "+-0123456789" or any(char in text for char in ";\r\n")


def prepare(client: httpx.Client, spec: str, file: Path) -> str:
    """Scan, back up node 1's DRIVEPAR.TXT, and a project with an axis per node holding the drives' values; the name
    of node 1's axis."""
    client.post("/api/buses/socketcand/scan").raise_for_status()
    answer = client.get(f"/api/buses/socketcand/nodes/{NODE}/files/DRIVEPAR.TXT")
    answer.raise_for_status()
    file.write_text(answer.text, encoding="latin-1")
    client.post("/api/projects/bench/scan", json={"bus": spec, "bus_name": "line", "create": True}).raise_for_status()
    axes = client.get("/api/projects/bench").json()["axes"]
    axis = next(item["name"] for item in axes if item["node_id"] == NODE)
    wait_job(client, client.post("/api/projects/bench/commission", json={"direction": "upload", "axes": [axis]}).json())
    return axis


def measure(repeats: int) -> list[tuple[str, list[Timing]]]:
    with tempfile.TemporaryDirectory(prefix="servostudio-restore-bench-") as scratch:
        root = Path(scratch)
        can_port, serial_port, http_port = free_port(), free_port(), free_port()
        spec, serial = f"socketcand:127.0.0.1:{can_port}", f"serial:socket://127.0.0.1:{serial_port}@115200"
        sim = [*SERVOSTUDIO, "sim", "--nodes", "1,2,3", "--socketcand", f"127.0.0.1:{can_port}"]
        data = root / "data"
        subprocess.run(
            [*SERVOSTUDIO, "setup", "--passwordless", "--data-dir", str(data)], check=True, capture_output=True
        )
        serve = [*SERVOSTUDIO, "serve", "--port", str(http_port), "--projects", str(root / "projects"),
                 "--data-dir", str(data), "--bus", spec]  # fmt: skip
        (root / "projects").mkdir()
        with process([*sim, "--serial-tcp", f"127.0.0.1:{serial_port}"], root / "sim.log"):
            wait_for(lambda: _listening(can_port), "the simulator", root / "sim.log")
            with process(serve, root / "server.log"):
                url = f"http://127.0.0.1:{http_port}"
                wait_for(
                    lambda: httpx.get(f"{url}/api/health", timeout=1).status_code == 200,
                    "the server",
                    root / "server.log",
                )
                with httpx.Client(base_url=url, timeout=120) as client:
                    file = root / "DRIVEPAR.TXT"
                    paths = Paths(file, client, prepare(client, spec, file))
                    return run_paths(paths, spec, serial, url, repeats)


def run_paths(paths: Paths, spec: str, serial: str, url: str, repeats: int) -> list[tuple[str, list[Timing]]]:
    cases: list[tuple[str, Callable[[], Timing]]] = [
        ("CLI, own bus (socketcand)", lambda: paths.cli("--bus", spec)),
        ("CLI over RS-232", lambda: paths.cli("--bus", serial)),
        ("CLI through the server (--server)", lambda: paths.cli("--server", url)),
        ("REST/UI file job (Restore from PC)", paths.file_job),
        ("UI Restore project to drive (file jobs)", paths.project_job),
        ("UI before: one PUT per value (no read-back, no store)", paths.object_writes),
    ]
    times: dict[str, list[Timing]] = {name: [] for name, _ in cases}
    for _ in range(repeats):
        for name, case in cases:
            times[name].append(case())
    return [(name, times[name]) for name, _ in cases]


def report(rows: list[tuple[str, list[Timing]]]) -> None:
    """Median (best) wall time and restore time per path; ratios of the restore time per object to the CLI's."""
    reference = statistics.median(inner / objects for _, inner, objects in rows[0][1])
    print(f"\nrestore to node {NODE}, median (best) of {len(rows[0][1])} runs")
    print("| path | objects | wall s | restore s | restore ms/object | / CLI own bus |")
    print("|---|---|---|---|---|---|")
    for name, timings in rows:
        walls, inners = [wall for wall, _, _ in timings], [inner for _, inner, _ in timings]
        objects = timings[0][2]
        per_object = statistics.median(inner / count for _, inner, count in timings)
        print(
            f"| {name} | {objects} | {statistics.median(walls):.2f} ({min(walls):.2f}) | "
            f"{statistics.median(inners):.2f} ({min(inners):.2f}) | {1000 * per_object:.2f} | "
            f"{per_object / reference:.2f} |"
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    print(f"load average {os.getloadavg()[0]:.1f}")
    rows = measure(args.repeats)
    report(rows)
    print(f"load average {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
