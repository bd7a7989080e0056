"""A process killed (SIGKILL) in the middle of project saves: the project stays intact — every file is the old or the
new one, never half of one — and what the interrupted save left behind is removed at the next start."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

from servostudio.od import builtin_library
from servostudio.services.projects import Axis, ProjectService

COUNTER = "0x3051"  # Digital inputs polarity, U16 rw, saved in DRIVEPAR.TXT

#: saves as fast as it can: a counter in DRIVEPAR.TXT and the project description (project.toml)
_SAVER = """
import itertools, sys
from pathlib import Path
from servostudio.od import builtin_library
from servostudio.services.projects import ProjectService

service = ProjectService(Path(sys.argv[1]), builtin_library())
service.library.load("xtrapulspac")
print("ready", flush=True)
for number in itertools.count(1):
    service.parameters.set("p", "X", {sys.argv[2]: number % 60000})
    service.store.update("p", description=f"save {number} " + "x" * (number % 4000))
"""


def _kill_mid_save(root: Path, after: float) -> None:
    saver = subprocess.Popen([sys.executable, "-c", _SAVER, str(root), COUNTER], stdout=subprocess.PIPE, text=True)
    assert saver.stdout is not None and saver.stdout.readline() == "ready\n"
    time.sleep(after)
    saver.send_signal(signal.SIGKILL)
    assert saver.wait(timeout=10) == -signal.SIGKILL


def test_a_project_killed_mid_save_is_intact_and_its_leftovers_go_at_the_next_start(sim_project: ProjectService):
    sim_project.store.add_axis("p", Axis("X", "xtrapulspac", 1, "sim"))
    root = sim_project.store.root
    for after in (0.3, 0.45, 0.6, 0.75):  # saves take about a millisecond each: a kill lands in one of them
        _kill_mid_save(root, after)
        fresh = ProjectService(root, builtin_library())  # what a restarted server opens
        assert fresh.store.open("p").project.description.startswith("save ")
        assert isinstance(fresh.parameters.get("p", "X", COUNTER)[0].value, int)  # DRIVEPAR.TXT parses whole
    (root / "p" / "X" / ".DRIVEPAR.TXT.left.tmp").write_bytes(b"0x3051,0=")  # as a kill mid-write leaves it
    (root / "p" / ".deleted-trash").mkdir()
    removed = ProjectService(root, builtin_library()).store.remove_stale_temporaries()
    assert removed >= 2
    assert [path.name for path in root.rglob(".*")] == []


def test_a_young_staging_directory_of_the_store_is_left_to_its_writer(sim_project: ProjectService):
    """An archive is unpacked into a staging directory of the store without the store lock: only one older than a
    save could take is stale."""
    root = sim_project.store.root
    young, old = root / ".new-unpacking", root / ".new-abandoned"
    young.mkdir()
    old.mkdir()
    os.utime(old, (time.time() - 3600, time.time() - 3600))
    assert sim_project.store.remove_stale_temporaries() == 1
    assert young.is_dir() and not old.exists()
