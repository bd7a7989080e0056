"""Real-time mode (`SimulatedNetwork.start()`) on a host too slow for the simulation: the thread runs small chunks
of virtual time per lock hold, and a frame from another thread enters the bus at the simulation's present instead
of waiting behind a catch-up burst. All assertions are about virtual time, which the host's speed cannot change."""

from __future__ import annotations

import threading
import time

import pytest
from tests.support.sim_test_drive import CountingBehaviour

from servostudio.sim.frame import Frame
from servostudio.sim.network import SimulatedNetwork

SLOW_STEP = 0.0004
"""Host seconds one 250 µs control period takes in these tests: the simulation cannot keep up with real time."""


class SlowBehaviour(CountingBehaviour):
    def step(self, dt: float) -> None:
        super().step(dt)
        time.sleep(SLOW_STEP)


class RecordingLock:
    """The network lock, recording the virtual time each hold by the simulation thread covered."""

    def __init__(self, network: SimulatedNetwork) -> None:
        self._lock = network.lock
        self._clock = network.clock
        self.spans: list[float] = []
        self._held_from: list[float] = []

    def __enter__(self) -> RecordingLock:
        self._lock.acquire()
        self._held_from.append(self._clock.now)
        return self

    def __exit__(self, *exc: object) -> None:
        start = self._held_from.pop()
        if threading.current_thread().name == "sim-clock":
            self.spans.append(self._clock.now - start)
        self._lock.release()

    def acquire(self, *args: object) -> bool:
        return self._lock.acquire(*args)

    def release(self) -> None:
        self._lock.release()


class Recorder:
    def __init__(self) -> None:
        self.frames: list[tuple[Frame, float]] = []

    def receive(self, frame: Frame, timestamp: float) -> None:
        self.frames.append((frame, timestamp))


@pytest.fixture
def slow_network(make_network):
    network = make_network("1,2", behaviour_factory=lambda device, node, store, events: SlowBehaviour(store, events))
    network.lock = RecordingLock(network)
    return network


def test_catching_up_runs_at_most_a_millisecond_of_virtual_time_per_lock_hold(slow_network):
    started = time.monotonic()
    slow_network.start()
    time.sleep(0.4)
    slow_network.stop()
    assert slow_network.now < time.monotonic() - started  # the host was too slow: the thread had to catch up
    spans = slow_network.lock.spans
    assert max(spans) <= 1e-3
    assert len(spans) > 50


def test_a_client_frame_enters_the_bus_at_the_simulations_present_while_it_lags(slow_network):
    recorder = Recorder()
    slow_network.attach(recorder)
    slow_network.start()
    sent_at: list[float] = []
    for number in range(30):
        time.sleep(0.01)
        sent_at.append(slow_network.now)  # the virtual present when the client sends (read without the lock)
        slow_network.inject(Frame(0x100 + number, bytes([number])))
    time.sleep(0.05)
    slow_network.stop()
    delivered = {
        frame.can_id - 0x100: timestamp for frame, timestamp in recorder.frames if 0x100 <= frame.can_id < 0x100 + 30
    }
    assert sorted(delivered) == list(range(30))
    # one chunk (250 µs) plus arbitration and the frame itself (≈ 0.1 ms): never a whole catch-up burst
    assert max(delivered[number] - sent_at[number] for number in range(30)) < 1e-3


def test_frames_posted_as_the_thread_stops_still_reach_the_bus(make_network):
    network = make_network("1")
    recorder = Recorder()
    network.attach(recorder)
    network.start()
    network.inject(Frame(0x123, b"\x01"))
    network.stop()
    network.advance(0.001)
    assert [frame.can_id for frame, _ in recorder.frames if frame.can_id == 0x123] == [0x123]
