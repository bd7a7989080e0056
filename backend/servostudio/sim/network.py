"""`SimulatedNetwork`: the simulated drives of one CAN bus, the clock that drives them, and the ways in.

Two ways to run time:
- tests call `advance(seconds)`: deterministic, as fast as the host allows;
- servers call `start()`: a background thread paces virtual time against the monotonic wall clock. It runs the
  events due in chunks of at most `CHUNK` virtual seconds, taking `lock` for one chunk at a time, and waits until
  the next event is due or a client's socket has data. The drives' control periods are lazy events (see
  `servostudio.sim.clock`): they run in order with the rest, but the thread wakes for them only every `IDLE_WAIT`
  when nothing else is due, so a frame a control period produces (a TPDO, an EMCY) may reach the clients up to that
  late in wall-clock time, with its exact virtual time stamp (as a USB CAN adapter delivers in 1 ms packets). When
  the host cannot keep up, virtual time stays at most `MAX_LAG` behind the wall clock: it slips (runs slower than
  real time) instead of catching up in a burst. While SYNCs from a client come at the drives' communication cycle
  period (0x1006), the thread follows them instead of the wall clock: the drives are SYNC-locked
  (`servostudio.sim.sync_lock`).
All access to the simulation goes through `lock`. Frames and actions from other threads enter with `inject` /
`post`: while the thread runs they wait in a queue that it empties after every chunk, so a client's frame never
waits for the lock behind a catch-up and enters the bus at the simulation's present.

Client sockets are read by that same thread (`watch`): a frame from a client reaches the bus without waking a
second thread, which on a loaded host costs more than the frame itself.
"""

from __future__ import annotations

import contextlib
import logging
import select
import socket
import threading
import time
from collections import deque
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from functools import partial
from pathlib import Path

from servostudio.od.library import EdsLibrary, builtin_library
from servostudio.od.model import ObjectDictionary
from servostudio.sim.bus import DEFAULT_BITRATE, Station, VirtualBus
from servostudio.sim.clock import CONTROL_PERIOD, VirtualClock
from servostudio.sim.events import DriveEvents
from servostudio.sim.frame import Frame
from servostudio.sim.node import Behaviour, SimulatedNode
from servostudio.sim.objects import ObjectStore
from servostudio.sim.sdo_server import DEFAULT_RESPONSE_TIME
from servostudio.sim.sync_lock import SyncLock, Window

log = logging.getLogger(__name__)

DEFAULT_DEVICE = "xtrapulspac"
CHUNK = CONTROL_PERIOD
"""Virtual seconds the real-time thread runs per lock hold; frames from clients enter between chunks."""
IDLE_WAIT = 1e-3
"""Longest sleep of the real-time thread when no event is due (a posted frame wakes it at once)."""
MAX_LAG = 0.05

DeviceBehaviourFactory = Callable[[str, int, ObjectStore, DriveEvents], Behaviour]
"""(device key, node ID, store, events) -> behaviour; the default builds servostudio.sim.drive behaviours."""


@dataclass(frozen=True)
class NodeSpec:
    node_id: int
    device: str


def parse_node_list(text: str, default_device: str = DEFAULT_DEVICE) -> list[NodeSpec]:
    """ "1,2,3" or "1:xtrapulspac,2:xtrapulspac,3:cd1k" -> node specs (IDs 1..127, each once)."""
    specs: list[NodeSpec] = []
    for item in text.split(","):
        item = item.strip()
        if not item:
            raise ValueError(f"node list {text!r}: empty entry")
        number, _, device = item.partition(":")
        try:
            node_id = int(number, 0)
        except ValueError:
            raise ValueError(f"node list {text!r}: {number!r} is not a node ID") from None
        if not 1 <= node_id <= 127:
            raise ValueError(f"node list {text!r}: node ID {node_id} is outside 1..127")
        if any(spec.node_id == node_id for spec in specs):
            raise ValueError(f"node list {text!r}: node ID {node_id} appears twice")
        specs.append(NodeSpec(node_id, device.strip().lower() or default_device))
    return specs


def drive_behaviour_factory(plant_file: Path | None = None, seed: int | None = None) -> DeviceBehaviourFactory:
    """Behaviours from `servostudio.sim.drive`, each node with its own plant (docs/sim-plant.md).

    The plant comes from `plant_file`, else is generated from `seed` + node ID (so drives differ); both give an
    uncommissioned drive (factory values, to be commissioned). With neither, the commissioned default machine.
    """
    from servostudio.sim.drive import make_behaviour
    from servostudio.sim.plant import Plant

    commissioned = plant_file is None and seed is None

    def factory(device: str, node_id: int, store: ObjectStore, events: DriveEvents) -> Behaviour:
        if plant_file is not None:
            plant = Plant.from_json(plant_file)
        elif seed is not None:
            plant = Plant.from_seed(seed + node_id)
        else:
            plant = Plant.commissioned()
        return make_behaviour(device, store, plant, events, commissioned)

    return factory


class SimulatedNetwork:
    def __init__(
        self,
        nodes: str | Iterable[NodeSpec | int],
        *,
        device: str = DEFAULT_DEVICE,
        library: EdsLibrary | None = None,
        dictionaries: dict[str, ObjectDictionary] | None = None,
        behaviour_factory: DeviceBehaviourFactory | None = None,
        bitrate: int | None = DEFAULT_BITRATE,
        sdo_response_time: float = DEFAULT_RESPONSE_TIME,
        state_dir: Path | None = None,
    ) -> None:
        specs = (
            parse_node_list(nodes, device)
            if isinstance(nodes, str)
            else [spec if isinstance(spec, NodeSpec) else NodeSpec(int(spec), device) for spec in nodes]
        )
        if not specs:
            raise ValueError("a simulated network needs at least one node")
        self.lock = threading.RLock()
        self.clock = VirtualClock()
        self.bus = VirtualBus(self.clock, bitrate)
        factory = behaviour_factory or drive_behaviour_factory()
        dictionaries = dict(dictionaries or {})
        library = library or builtin_library()
        self.nodes: dict[int, SimulatedNode] = {}
        for spec in specs:
            if spec.device not in dictionaries:
                dictionaries[spec.device] = library.load(spec.device)
            self.nodes[spec.node_id] = SimulatedNode(
                spec.node_id,
                dictionaries[spec.device],
                self.clock,
                self.bus,
                partial(factory, spec.device, spec.node_id),
                state_dir=state_dir,
                sdo_response_time=sdo_response_time,
            )
        self._ticks = 0
        self._node_list = list(self.nodes.values())
        self.clock.call_at(CONTROL_PERIOD, self._tick, lazy=True)
        #: while running, SYNCs from outside lock the drives' cycle (servostudio.sim.sync_lock)
        self.sync_lock = SyncLock(self._cycle_periods)
        self._speed = 1.0
        self._origin = (0.0, 0.0)  # while running free: the (wall, virtual) instants its time counts from
        self._thread: threading.Thread | None = None
        self._stop = threading.Event()
        self._posted: deque[Callable[[], None]] = deque()
        self._readers: dict[int, Callable[[], None]] = {}  # watched descriptor -> its callback
        self._wake_pair: tuple[socket.socket, socket.socket] | None = None  # (read end, write end) while running

    # -- nodes ----------------------------------------------------------------------------------------------------

    def node(self, node_id: int) -> SimulatedNode:
        return self.nodes[node_id]

    @property
    def first_node(self) -> SimulatedNode:
        return self._node_list[0]

    # -- time -----------------------------------------------------------------------------------------------------

    def _tick(self) -> None:
        self._ticks += 1
        # Scheduled first, so a failing step cannot stop time.
        self.clock.call_at((self._ticks + 1) * CONTROL_PERIOD, self._tick, lazy=True)
        for node in self._node_list:
            node.step(CONTROL_PERIOD)

    def advance(self, seconds: float) -> None:
        """Run the simulation `seconds` of virtual time forward (deterministic; not while `start()`ed)."""
        if self.running:
            raise RuntimeError("advance() cannot step a network whose real-time thread is running")
        with self.lock:
            self._run_posted()
            self.clock.run_until(self.clock.now + seconds)

    @property
    def now(self) -> float:
        return self.clock.now

    @property
    def running(self) -> bool:
        return self._thread is not None and self._thread.is_alive()

    def start(self, speed: float = 1.0) -> None:
        """Run in real time on a background (daemon) thread until `stop()`; while free-running (no SYNC lock),
        ``speed`` virtual seconds per wall-clock second (tests run faster than real time)."""
        if self.running:
            return
        self._speed = speed
        self._stop.clear()
        pair = self._wake_pair = socket.socketpair()
        for end in pair:
            end.setblocking(False)
        self._thread = threading.Thread(target=self._run, args=(pair[0],), name="sim-clock", daemon=True)
        self._thread.start()

    def stop(self) -> None:
        self._stop.set()
        self._wake()
        if self._thread is not None:
            self._thread.join()
            self._thread = None
        if self._wake_pair is not None:
            for end in self._wake_pair:
                end.close()
            self._wake_pair = None
        with self.lock:
            self._run_posted()  # frames that arrived while the thread was ending

    def _run(self, wake: socket.socket) -> None:
        """The clock thread; `wake` is the read end of the wake-up pair, open until the thread has ended."""
        self._origin = (time.monotonic(), self.clock.now)  # (wall, virtual) instants free-running time counts from
        locked: Window | None = None
        while not self._stop.is_set():
            with self.lock:
                was_locked, locked = locked, self.sync_lock.window(time.monotonic())
                if was_locked is not None and locked is None:  # the SYNCs ended: free-running from here
                    self._origin = (time.monotonic(), self.clock.now)
                target = self._target(self._origin, locked)
                self._run_chunk(min(target, self.clock.now + CHUNK))
                behind = target - self.clock.now
                due = self.clock.next_event_time()
            if behind > MAX_LAG and locked is None:  # slip: the host is too slow
                self._origin = (self._origin[0] + (behind - MAX_LAG) / self._speed, self._origin[1])
            wait = 0.0
            if behind <= 0:  # until the next event, counted from now: running the chunk took time too
                present = self._target(self._origin, locked)
                wait = IDLE_WAIT if due is None else min(IDLE_WAIT, due - present)
            self._wait_for_readers(wake, max(wait, 0.0))

    def _target(self, origin: tuple[float, float], locked: Window | None) -> float:
        """The virtual time due now: paced from ``origin``, or while SYNC-locked from the last slot to its ceiling."""
        if locked is None:
            return origin[1] + (time.monotonic() - origin[0]) * self._speed
        return min(locked.slot + (time.monotonic() - locked.wall) * self._speed, locked.ceiling)

    def _cycle_periods(self) -> set[float]:
        return {period for node in self._node_list if (period := node.cycle_period()) > 0}

    def _transmit_from_outside(self, frame: Frame, sender: Station | None, sent: float) -> None:
        """A client's frame onto the bus; while running, a SYNC first runs the drives to its slot (sync_lock), or —
        free-running — to the instant it was sent (``sent``, monotonic): a real drive answers a SYNC when it comes,
        and the SYNCs a starved clock thread finds queued must not all be answered at one virtual instant."""
        if self.running and any(node.consumes_sync(frame) for node in self._node_list):
            slot = self.sync_lock.slot(self.clock.now, sent)
            if not self.sync_lock.locked:
                slot = max(slot, self._origin[1] + (sent - self._origin[0]) * self._speed)
            if slot > self.clock.now:
                self.clock.run_until(slot)
        self.bus.transmit(frame, sender)

    def _wait_for_readers(self, wake: socket.socket, seconds: float) -> None:
        """Wait up to `seconds` for a watched socket or a wake-up, and serve what is readable. `select` waits to the
        microsecond; epoll and poll round up to whole milliseconds, longer than an SDO frame."""
        watched: list[socket.socket | int] = [wake, *self._readers]
        readable, _, _ = select.select(watched, [], [], seconds)
        for descriptor in readable:
            if descriptor is wake:
                self._drain_wake(wake)
            elif descriptor in self._readers:
                self._readers[descriptor]()

    def _run_chunk(self, until: float) -> None:
        """Events due up to `until`, then the frames posted meanwhile (lock held); a failing event is dropped."""
        try:
            self.clock.run_until(until)
        except Exception:  # keep serving the other drives and clients; the failed event is dropped
            log.exception("simulation event failed at t=%.6f s", self.clock.now)
        self._run_posted()

    def _run_posted(self) -> None:
        posted = self._posted
        while posted:
            action = posted.popleft()
            try:
                action()
            except Exception:
                log.exception("action posted from outside failed at t=%.6f s", self.clock.now)

    def __enter__(self) -> SimulatedNetwork:
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()

    # -- frames from outside --------------------------------------------------------------------------------------

    def attach(self, station: Station) -> None:
        with self.lock:
            self.bus.attach(station)

    def detach(self, station: Station) -> None:
        with self.lock:
            self.bus.detach(station)

    def inject(self, frame: Frame, sender: Station | None = None) -> None:
        """Put a frame from outside (client, socketcand, serial) on the bus at the current virtual time."""
        sent = time.monotonic()
        self.post(lambda: self._transmit_from_outside(frame, sender, sent))

    def post(self, action: Callable[[], None]) -> None:
        """Run `action` inside the simulation: while running, on its thread after the current chunk (the caller does
        not wait for the lock); otherwise at once, under the lock."""
        if self.running:
            self._posted.append(action)
            if threading.current_thread() is not self._thread:
                self._wake()
            return
        with self.lock:
            self._run_posted()
            action()

    def watch(self, connection: socket.socket, on_readable: Callable[[], None]) -> None:
        """Call `on_readable()` on the simulation thread (lock not held) whenever `connection` has data, until
        `unwatch_and_close`. It should read without blocking and hand frames to `inject`. Sockets are served while the
        network runs (`start()`); `advance()` does not read them."""
        connection.setblocking(False)
        descriptor = connection.fileno()

        def register() -> None:
            self._readers[descriptor] = on_readable

        self.post(register)

    def unwatch_and_close(self, connection: socket.socket) -> None:
        """Stop watching `connection` and close it, on the simulation thread: a descriptor closed while `select`
        still waits on it would fail the wait. In posting order, so a new connection that reuses the number is
        watched after this."""
        descriptor = connection.fileno()

        def forget_and_close() -> None:
            self._readers.pop(descriptor, None)
            connection.close()

        self.post(forget_and_close)

    def _wake(self) -> None:
        pair = self._wake_pair
        if pair is None:
            return
        with contextlib.suppress(BlockingIOError, OSError):  # plenty of wake-ups pending, or stopping: it wakes anyway
            pair[1].send(b"\0")

    @staticmethod
    def _drain_wake(wake: socket.socket) -> None:
        try:
            while wake.recv(4096):
                pass
        except BlockingIOError:
            pass

    def open_bus(self, channel: str = "sim", **kwargs: object):
        """A python-can bus attached to this network (e.g. `canopen.Network(network.open_bus())`)."""
        from servostudio.sim.inprocess import SimulatedCanBus

        return SimulatedCanBus(self, channel=channel, **kwargs)
