"""The communication server's buses: several open at once, each with its SDO engine, monitor and known drives.

A bus is opened from a spec string (``servostudio.transport.spec``).  ``sim`` builds simulated drives in this
process.  A bus whose interface is missing or lost stays registered and reconnects by itself; its state changes
are published as ``bus_state`` events.
"""

from __future__ import annotations

import itertools
import threading
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from typing import Protocol

import can

from servostudio.drive.access import OPEN_GATE, Drive, WriteGate
from servostudio.drive.link import BusLink
from servostudio.drive.monitor import BusMonitor, DriveStateReporter
from servostudio.drive.nmt import NmtCommand, NmtHeard, guard_nmt, send_nmt
from servostudio.drive.profibus.engine import PkwEngine
from servostudio.drive.profibus.link import ProfibusLink, refusal
from servostudio.drive.profiles import DeviceProfile, profile_for
from servostudio.drive.sdo import SdoEngine
from servostudio.errors import Conflict, InvalidInput, NotFound, ServoStudioError
from servostudio.od.library import EdsLibrary, builtin_library
from servostudio.od.pnu_model import ParameterDictionary
from servostudio.services.bus.claims import BusClaims
from servostudio.services.bus.events import EventHub
from servostudio.services.bus.share import BusShare, NotShared, ShareStatus
from servostudio.services.bus.statewatch import StatuswordWatch
from servostudio.services.motion import MotionGuard
from servostudio.transport.open import open_bus
from servostudio.transport.profibus.open import open_dp_line
from servostudio.transport.spec import BusSpec, parse_bus_spec

SERIAL_SDO_TIMEOUT = 1.0  # at 19200 baud a request and its answer alone take 12.5 ms, a forwarded one more
CAN_SDO_TIMEOUT = 0.5
DEFAULT_SHARE_HOST = "127.0.0.1"
TTAPRO = "ttapro"


class UnknownBusOrNode(NotFound):
    """Unknown bus or node."""


class BusNameTaken(Conflict):
    """Another bus is already open under the name asked for."""


@dataclass(frozen=True)
class BusMatch:
    """Which open bus a project's bus is: ``by`` ``name`` (same name and spec), ``spec`` (the spec is open under
    another name), ``name_only`` (an open bus of that name has another spec), or None (not open)."""

    name: str
    spec: str
    bus: str | None
    by: str | None

    def as_dict(self) -> dict[str, object]:
        return asdict(self)


def parse_share(text: str) -> tuple[str, str, int]:
    """``BUS=PORT`` or ``BUS=HOST:PORT`` (``serve --share``) → (bus name or spec, host, port)."""
    bus, equals, address = text.rpartition("=")
    host, _, port = address.rpartition(":")
    if not equals or not bus or not port.isdigit():
        raise BadShare(f"--share {text!r}: expected BUS=PORT or BUS=HOST:PORT, e.g. sim=29540")
    return bus, host.strip("[]") or DEFAULT_SHARE_HOST, int(port)


class BadShare(InvalidInput):
    """A ``--share`` that is not BUS=[HOST:]PORT."""


class BusAlreadyOpen(Conflict):
    """The spec asked for under a new name is open already, under its own name."""


def parameter_list(library: EdsLibrary, info: NodeInfo | None) -> ParameterDictionary | None:
    """The PNUs of a PROFIBUS node: its device's parameter list (the TTA-PRO's until a scan said otherwise)."""
    dictionary = library.load(info.device if info is not None and info.device else TTAPRO)
    return dictionary if isinstance(dictionary, ParameterDictionary) else None


class Simulation(Protocol):
    def stop(self) -> None: ...


@dataclass
class NodeInfo:
    """What a scan learned about a node."""

    node: int
    device: str | None = None
    device_type: int | None = None
    vendor_id: int | None = None
    product_code: int | None = None
    revision: int | None = None
    serial_number: int | None = None
    device_name: str | None = None
    hardware_version: str | None = None
    software_version: str | None = None

    def as_dict(self) -> dict[str, object]:
        return asdict(self)


@dataclass
class BusConnection:
    """One open bus."""

    id: str
    spec: BusSpec
    link: BusLink
    engine: SdoEngine
    library: EdsLibrary
    events: EventHub
    nodes: dict[int, NodeInfo] = field(default_factory=dict)
    simulation: Simulation | None = None  # the simulated drives of a ``sim`` bus, stopped with it
    gate: WriteGate = OPEN_GATE  # every write of the bus's drives passes it: the manager's motion guard
    monitor: BusMonitor | None = None
    #: a bus without CAN frames (PROFIBUS-DP): its drive_state events from the status words its engine receives
    drive_states: DriveStateReporter | None = None
    share: BusShare | None = None  # its socketcand endpoint for the user's own scripts, when shared
    motion: MotionGuard | None = None  # judges and logs its NMT commands (the manager's guard)
    #: the nodes and the SYNC its running jobs hold (captures, rolls, frequency responses, identifications)
    claims: BusClaims = field(init=False, repr=False)
    _identifying: dict[int, threading.Lock] = field(default_factory=dict, repr=False)
    _identifying_guard: threading.Lock = field(default_factory=threading.Lock, repr=False)

    def drive(self, node: int, device: str | None = None) -> Drive:
        """Drive access for a node: ``device`` if given, else the device a scan found (a node not scanned yet is
        identified now; one that does not answer gets a Drive without dictionary, which refuses typed access)."""
        if not 1 <= node <= 127:
            raise UnknownBusOrNode(f"node ID {node} outside 1..127")
        device = device or self._device_of(node)
        dictionary = self.library.load(device) if device else None
        return Drive(self.engine, node, dictionary, profile_for(device), self.gate)

    def _device_of(self, node: int) -> str | None:
        """The node's device, identifying it first when unknown.

        A node whose identity could not be read (no vendor ID: its answers were lost, e.g. under load) is
        identified again rather than left without dictionary until the next scan.  Concurrent first requests
        for one node identify it once: the others wait for that answer.
        """
        info = self.nodes.get(node)
        if (info is not None and info.vendor_id is not None) or not self.link.connected:
            return info.device if info else None
        with self._identifying_guard:
            lock = self._identifying.setdefault(node, threading.Lock())
        with lock:
            info = self.nodes.get(node)
            if info is None or info.vendor_id is None:
                from servostudio.services.scan import identify  # scan builds on this module

                info = identify(self, node)
        return info.device if info else None

    def __post_init__(self) -> None:
        self.claims = BusClaims(self.id)
        if self.motion is not None:
            guard_nmt(self.link, self._judge_nmt)

    def nmt(self, command: str, node: int = 0) -> NmtCommand:
        """Send an NMT command named as the CLI and REST name it (``start``, ``reset-node``, …); node 0: all.
        A PROFIBUS line has no NMT: refused before the motion guard is asked about a command nobody would hear."""
        parsed = NmtCommand.parse(command)
        if isinstance(self.link, ProfibusLink):
            raise refusal(self.id, "an NMT command")
        send_nmt(self.link, parsed, node)
        return parsed

    def _judge_nmt(self, command: NmtCommand, node: int) -> NmtHeard:
        """A start can make an axis move and a reset stop it, so the motion guard judges every NMT command sent on
        this bus — by anyone — for every node it addresses (node 0: every node a scan found) and logs it, as it
        does writes (``docs/motion-safety.md``)."""
        assert self.motion is not None
        return self.motion.admit_nmt(self.id, command, self._nmt_targets(node))

    def _nmt_targets(self, node: int) -> list[tuple[int, Drive, str | None]]:
        """The nodes an NMT command to ``node`` reaches, with their drives and NMT states (none when out of range:
        ``send_nmt`` refuses it)."""
        nodes = [node] if 1 <= node <= 127 else sorted(self.nodes) if node == 0 else []
        return [(each, self.drive(each), self.nmt_state(each)) for each in nodes]

    def report_statusword(self, node: int, statusword: int) -> None:
        """Publish a drive_state event when a status word read elsewhere shows a state change."""
        reporter = self.monitor or self.drive_states
        if reporter is not None:
            reporter.report_statusword(node, statusword)

    def nmt_state(self, node: int) -> str | None:
        """The node's NMT state as its last heartbeat or boot-up said (None before any)."""
        return self.monitor.nmt_state(node) if self.monitor is not None else None

    def profile_of(self, node: int) -> DeviceProfile | None:
        info = self.nodes.get(node)
        return profile_for(info.device) if info and info.device else None

    def status(self) -> dict[str, object]:
        return {
            "id": self.id,
            "spec": str(self.spec),
            "kind": self.spec.kind,
            "connected": self.link.connected,
            "error": self.link.last_error or None,
            "nodes": [info.as_dict() for info in sorted(self.nodes.values(), key=lambda item: item.node)],
        }

    def share_on(self, host: str = DEFAULT_SHARE_HOST, port: int = 0) -> ShareStatus:
        """Share the bus as a socketcand endpoint (port 0: any free one); an existing share is kept as it is."""
        if self.share is None:
            self.share = BusShare(self, host, port)
        return self.share.status()

    def shared(self) -> ShareStatus:
        """The bus's share, or `NotShared`."""
        if self.share is None:
            raise NotShared(f"bus {self.id} is not shared")
        return self.share.status()

    def share_off(self) -> None:
        share, self.share = self.share, None
        if share is not None:
            share.close()

    def close(self) -> None:
        self.share_off()
        self.link.close()
        if self.simulation is not None:
            self.simulation.stop()


class ConnectionManager:
    """All buses of the server (or of one CLI command)."""

    def __init__(
        self, library: EdsLibrary | None = None, events: EventHub | None = None, motion: MotionGuard | None = None
    ) -> None:
        self.library = library or builtin_library()
        self.events = events or EventHub()
        #: every drive of every bus writes through it (one of its own unless the server shares one)
        self.motion = motion if motion is not None else MotionGuard(self.events.publish)
        self._buses: dict[str, BusConnection] = {}
        self._lock = threading.Lock()

    def open(self, spec_text: str, bus_id: str | None = None, wait: float = 2.0) -> BusConnection:
        """Open (or re-use) the bus a spec names; waits up to ``wait`` s for the first connection.

        The same spec (any spelling of it) is one bus: it is returned under its name, whatever ``bus_id`` asks
        (`opened` tells a caller that must say so)."""
        spec = parse_bus_spec(spec_text)
        with self._lock:
            for existing in self._buses.values():
                if existing.spec == spec:
                    return existing
            bus_id = bus_id or self._free_id(spec.kind)
            if bus_id in self._buses:
                raise BusNameTaken(f"a bus named {bus_id!r} is already open")
        if spec.kind == "profibus":
            return self._open_profibus(spec, bus_id)
        opener, simulation = self._opener(spec)
        link = BusLink(bus_id, opener)
        timeout = SERIAL_SDO_TIMEOUT if spec.kind == "serial" else CAN_SDO_TIMEOUT
        connection = BusConnection(
            bus_id,
            spec,
            link,
            SdoEngine(link, timeout),
            self.library,
            self.events,
            simulation=simulation,
            gate=self.motion.gate(bus_id),
            motion=self.motion,
        )
        connection.monitor = BusMonitor(link, self.events.publish, connection.profile_of)
        StatuswordWatch(connection, lambda: self.events.wants("drive_state"))
        link.on_state(
            lambda connected, reason: self.events.publish(
                {"type": "bus_state", "bus": bus_id, "connected": connected, "reason": reason}
            )
        )
        with self._lock:
            self._buses[bus_id] = connection
        link.start(wait)
        return connection

    def _open_profibus(self, spec: BusSpec, bus_id: str) -> BusConnection:
        """A PROFIBUS-DP line (docs/profibus.md §9): its drives are ordinary `Drive`s on their parameter list with
        the PKW engine in place of the SDO engine; no bus monitor (no CAN frames to watch), but drive_state events from
        the PZD status word of every station in data exchange (``PkwEngine.on_status_word``). The master is the line's
        (`open_dp_line`: pyprofibus for a serial device, the project's own for a TCP stream). A line that cannot be
        opened is refused at once (`DpLinkError`, 503): there is no interface to wait for."""
        link = ProfibusLink(bus_id, open_dp_line(spec))
        engine = PkwEngine(link, lambda node: parameter_list(self.library, connection.nodes.get(node)))
        connection = BusConnection(
            bus_id,
            spec,
            link,
            engine,
            self.library,
            self.events,
            gate=self.motion.gate(bus_id),
            motion=self.motion,
        )
        connection.drive_states = DriveStateReporter(bus_id, self.events.publish)
        engine.on_status_word(connection.drive_states.report_statusword)
        with self._lock:
            self._buses[bus_id] = connection
        link.start()
        return connection

    def _free_id(self, kind: str) -> str:
        """A readable default name: the bus kind ("sim", "socketcand"), numbered when that name is taken."""
        candidates = itertools.chain([kind], (f"{kind}{number}" for number in itertools.count(2)))
        return next(name for name in candidates if name not in self._buses)

    def _opener(self, spec: BusSpec) -> tuple[Callable[[], can.BusABC], Simulation | None]:
        if spec.kind != "sim":
            return (lambda: open_bus(spec)), None
        from servostudio.sim.network import SimulatedNetwork

        network = SimulatedNetwork(spec.channel)
        network.start()
        return (lambda: network.open_bus()), network

    def opened(self, spec_text: str, bus_id: str | None = None, wait: float = 2.0) -> tuple[BusConnection, bool]:
        """`open`, and whether the bus was open already.  An open spec asked for under another name is refused
        (`BusAlreadyOpen`, naming it): one bus has one name, and a caller that wanted a second bus must know."""
        existing = self.find(spec_text)
        if existing is None:
            return self.open(spec_text, bus_id, wait), False
        if bus_id is not None and bus_id != existing.id:
            raise BusAlreadyOpen(f"{existing.spec} is open already as bus {existing.id!r}; use that name")
        return existing, True

    def find(self, spec_text: str) -> BusConnection | None:
        """The open bus of a spec, however it is spelt (``socketcand:h:p`` is ``socketcand:h:p/can0``)."""
        spec = parse_bus_spec(spec_text)
        return next((bus for bus in self._buses.values() if bus.spec == spec), None)

    def match(self, name: str, spec_text: str) -> BusMatch:
        """The open bus a project's bus (its name and spec) is: the one with its spec, else the one of its name."""
        try:
            by_spec = self.find(spec_text)
        except ServoStudioError:
            by_spec = None
        if by_spec is not None:
            return BusMatch(name, spec_text, by_spec.id, "spec" if by_spec.id != name else "name")
        if name in self._buses:
            return BusMatch(name, spec_text, name, "name_only")
        return BusMatch(name, spec_text, None, None)

    def share(self, bus: str, host: str = DEFAULT_SHARE_HOST, port: int = 0) -> ShareStatus:
        """Share an open bus (by name or spec) as a socketcand endpoint for the user's own scripts."""
        return self.named(bus).share_on(host, port)

    def named(self, bus: str) -> BusConnection:
        """An open bus by its name, or by its spec however spelt."""
        if bus in self._buses:
            return self._buses[bus]
        try:
            found = self.find(bus)
        except ServoStudioError:
            found = None
        return found if found is not None else self.get(bus)

    def get(self, bus_id: str) -> BusConnection:
        try:
            return self._buses[bus_id]
        except KeyError:
            known = ", ".join(self._buses) or "none"
            raise UnknownBusOrNode(f"no bus {bus_id!r} (open buses: {known})") from None

    def list(self) -> list[BusConnection]:
        return list(self._buses.values())

    def close(self, bus_id: str) -> None:
        with self._lock:
            connection = self._buses.pop(bus_id, None)
        if connection is None:
            raise UnknownBusOrNode(f"no bus {bus_id!r}")
        connection.close()
        self.events.publish({"type": "bus_closed", "bus": bus_id})

    def close_all(self) -> None:
        for bus_id in list(self._buses):
            self.close(bus_id)
