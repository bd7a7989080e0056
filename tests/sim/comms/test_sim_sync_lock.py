"""The simulator's drives synchronise their cycle to the SYNC (sim/sync_lock.py), in real-time mode: SYNCs from a
client at the communication cycle period 0x1006 enter the bus exactly one period apart in virtual time, however
bunched they leave the client (a loaded host's SYNC thread); SYNCs at another period leave the simulation
free-running, and so does the end of the stream. Observed on the bus, in virtual time."""

from __future__ import annotations

import itertools
import time

import pytest

from servostudio.sim.network import SimulatedNetwork
from servostudio.sim.sync_lock import AGREE, UNLOCK_AFTER_S

PERIOD_US = 1000
BURST = 4


def sync_times(period_us: int, count: int, probe: bool = False) -> list[float]:
    """Virtual times the SYNCs reached a second client; they leave in bursts of ``BURST`` (mean spacing 1 ms), after
    a single SYNC 0.15 s before them with ``probe`` (as a scope capture starts)."""
    network = SimulatedNetwork("1")
    network.start()
    try:
        with network.lock:
            network.node(1).store.set(0x1006, 0, period_us)
        sender, listener = network.open_bus(), network.open_bus()
        if probe:
            sender.send_frame(0x080, b"")
            time.sleep(0.15)
        start = time.monotonic()
        for k in range(count):
            if k % BURST == 0:
                time.sleep(max(0.0, start + k * PERIOD_US * 1e-6 - time.monotonic()))
            sender.send_frame(0x080, b"")
        time.sleep(0.05)
        frames = listener.receive_frames(0.1)
        return [stamp for cob_id, _, stamp, _ in frames if cob_id == 0x080][int(probe) :]
    finally:
        network.stop()


def test_syncs_at_the_configured_period_come_one_period_apart_in_the_drives_time():
    times = sync_times(PERIOD_US, AGREE + 200)
    spacings = [b - a for a, b in itertools.pairwise(times)]
    assert len(times) == AGREE + 200
    assert all(abs(spacing - PERIOD_US * 1e-6) < 1e-9 for spacing in spacings[-100:])  # locked after a loaded start


@pytest.mark.parametrize("probe", [False, True])
def test_syncs_at_another_period_leave_the_simulation_free_running(probe):
    times = sync_times(10 * PERIOD_US, AGREE + 60, probe)  # the XtrapulsPac's default 0x1006 against 1-ms SYNCs
    spacings = [b - a for a, b in itertools.pairwise(times)]
    assert min(spacings[AGREE:]) < 0.5 * PERIOD_US * 1e-6  # the bursts reach the drive as they left the client


def test_the_end_of_the_stream_unlocks():
    network = SimulatedNetwork("1")
    network.start()
    try:
        with network.lock:
            network.node(1).store.set(0x1006, 0, PERIOD_US)
        sender = network.open_bus()
        start = time.monotonic()
        for k in range(AGREE + 200):
            time.sleep(max(0.0, start + k * PERIOD_US * 1e-6 - time.monotonic()))
            sender.send_frame(0x080, b"")
        time.sleep(0.02)
        assert network.sync_lock.locked
        held = network.now
        time.sleep(UNLOCK_AFTER_S + 0.2)
        assert not network.sync_lock.locked
        assert network.now - held > 0.1  # virtual time runs with the wall clock again
    finally:
        network.stop()
