"""Concurrent edits of one project from threads and processes: no lost update, no corrupt file."""

from __future__ import annotations

import subprocess
import sys
import threading
from pathlib import Path

from servostudio.od import builtin_library
from servostudio.services.projects import Axis, ConflictError, ProjectService

COUNTER = "0x3051"  # Digital inputs polarity, U16 rw, saved in DRIVEPAR.TXT


def _increment(root: Path, times: int) -> int:
    """Read-modify-write with the revision check, retrying on conflict; returns how many conflicts it saw."""
    service = ProjectService(root, builtin_library())
    conflicts = 0
    for _ in range(times):
        while True:
            row, revision = service.parameters.get("p", "X", COUNTER)
            try:
                service.parameters.set("p", "X", {COUNTER: row.value + 1}, expected_revision=revision)
                break
            except ConflictError:
                conflicts += 1
    return conflicts


def _prepare(service: ProjectService) -> None:
    service.store.add_axis("p", Axis("X", "xtrapulspac", 1, "sim"))
    service.parameters.set("p", "X", {COUNTER: 0})


def _no_leftovers(root: Path) -> None:
    assert [path.name for path in root.rglob(".*")] == []


def test_threads_never_lose_an_update(sim_project: ProjectService):
    _prepare(sim_project)
    root = sim_project.store.root
    threads = [threading.Thread(target=_increment, args=(root, 25)) for _ in range(3)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    row, _ = sim_project.parameters.get("p", "X", COUNTER)
    assert row.value == 75
    _no_leftovers(root)


_WORKER = """
import sys
from pathlib import Path
from servostudio.od import builtin_library
from servostudio.services.projects import ConflictError, ProjectService

service = ProjectService(Path(sys.argv[1]), builtin_library())
service.library.load("xtrapulspac")
print("ready", flush=True)
sys.stdin.readline()
for _ in range(int(sys.argv[2])):
    while True:
        row, revision = service.parameters.get("p", "X", sys.argv[3])
        try:
            service.parameters.set("p", "X", {sys.argv[3]: row.value + 1}, expected_revision=revision)
            break
        except ConflictError:
            pass
"""


def test_processes_never_lose_an_update(sim_project: ProjectService):
    _prepare(sim_project)
    root = sim_project.store.root
    workers = [
        subprocess.Popen(
            [sys.executable, "-c", _WORKER, str(root), "20", COUNTER],
            text=True,
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
        )
        for _ in range(2)
    ]
    assert [worker.stdout.readline() for worker in workers] == ["ready\n", "ready\n"]
    for worker in workers:  # both are loaded: start them together so their edits interleave
        worker.stdin.write("go\n")
        worker.stdin.close()
    assert [worker.wait(timeout=90) for worker in workers] == [0, 0]
    row, _ = sim_project.parameters.get("p", "X", COUNTER)
    assert row.value == 40
    _no_leftovers(root)


def test_blind_writes_from_threads_all_land(sim_project: ProjectService):
    """Without a revision, writers are serialised: each write sees the others' values, none is dropped."""
    _prepare(sim_project)

    def writer(first_input: int) -> None:
        service = ProjectService(sim_project.store.root, builtin_library())
        for number in range(first_input, first_input + 5):
            service.parameters.set("p", "X", {f"0x3050,{number}": 0x60FD0000 + number})
            service.store.update("p", description=f"written by input {number}")

    threads = [threading.Thread(target=writer, args=(first,)) for first in (1, 6)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    rows, _ = sim_project.parameters.rows("p", "X", only_set=True)
    assert {(row.variable.subindex, row.value) for row in rows if row.variable.index == 0x3050} == {
        (number, 0x60FD0000 + number) for number in range(1, 11)
    }
    assert sim_project.store.open("p").project.description.startswith("written by input ")
