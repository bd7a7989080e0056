"""The frequency response on the server's own simulator, as ``make run`` starts it (``servostudio serve`` with the
embedded ``sim`` bus, nothing of the tests in its clock): the measurement goes through the REST route (``servostudio
--server URL bode``) and meets the accuracy of the service tests on a HIDDEN seeded plant, because the simulated
drive locks its cycle to the measurement's SYNC by itself (sim/sync_lock.py). Only the plant is the test's: the
drives are commissioned for a seeded plant instead of the default machine.
"""

from __future__ import annotations

import csv
import os
import subprocess
import sys
import threading

import pytest
from tests.support.motion_timing import InProcessServer
from tests.support.plant_truth import free, plant_error

from servostudio.sim import network as sim_network
from servostudio.sim.drive import make_behaviour
from servostudio.sim.plant import Plant

SEED = 14  # rigid, not one the service tests use


@pytest.fixture
def server(tmp_path, monkeypatch):
    plant = free(Plant.from_seed(SEED))
    monkeypatch.setattr(
        sim_network,
        "drive_behaviour_factory",
        lambda: lambda device, node, store, events: make_behaviour(device, store, plant, events, True),
    )
    running = InProcessServer(tmp_path)
    yield running, plant
    running.close()


def watch_lock(running: InProcessServer, seen: set[bool], finished: threading.Event) -> None:
    """Whether the simulation was SYNC-locked, sampled every 20 ms until ``finished``."""
    while not finished.wait(0.02):
        seen.add(running.network.sync_lock.locked)


def test_a_plant_measured_through_rest_on_the_servers_simulator_is_accurate(server, tmp_path):
    running, plant = server
    out = tmp_path / "plant.csv"
    options = ("--amplitude", "100", "--base-speed", "15", "--periods", "4", "--window", "40", "--yes")
    seen, finished = set(), threading.Event()
    watcher = threading.Thread(target=watch_lock, args=(running, seen, finished), daemon=True)
    watcher.start()
    done = subprocess.run(
        [sys.executable, "-m", "servostudio", "--server", running.url, "bode", "--bus", "sim", "--node", "1",
         "--loop", "plant", *options, "--out", str(out)],
        capture_output=True, text=True, timeout=120, env=dict(os.environ),
    )  # fmt: skip
    finished.set()
    watcher.join()
    assert done.returncode == 0, done.stderr
    assert seen == {False, True}  # free-running, then locked to the measurement's SYNC
    lines = [line for line in out.read_text(encoding="utf-8").splitlines() if not line.startswith("#")]
    points = [{key: float(value) for key, value in row.items()} for row in csv.DictReader(lines)]
    band = [point for point in points if 4.9 <= point["freq_hz"] <= 200.0]
    assert band[0]["freq_hz"] == pytest.approx(5.0, rel=0.01) and band[-1]["freq_hz"] > 190.0
    errors = [plant_error(point, plant) for point in band]
    assert max(abs(db) for db, _ in errors) < 1.0, errors
    assert max(abs(deg) for _, deg in errors) < 10.0, errors
    assert min(point["coherence"] for point in band) > 0.95
    assert not running.network.sync_lock.locked  # free-running again once the SYNCs ended
    with running.network.lock:
        assert running.network.node(1).store.get(0x1006, 0) == 10000  # the cycle period written back
