"""One simulated CANopen drive: NMT state machine, SDO servers, PDOs, SYNC, error control, EMCY, flash files.

The node owns an `ObjectStore` built from the device's dictionary and one drive behaviour (built by the factory it
is given, which receives the store and the node's `DriveEvents`). It speaks only CAN frames: `receive` takes what
the bus delivers, `handle_local` what the serial link hands to the drive directly; everything it sends goes through
`transmit` onto the bus.

NMT reset (0x205D bits 0–3 on the XtrapulsPac; a device without 0x205D does a full reset):
- reset communication: 0x1000–0x1FFF back to their power-on values (defaults, then the DRIVEPAR.TXT values of that
  range), SDO transfers dropped, boot-up;
- reset node, mode 0: as reset communication; mode 1: DRIVEPAR.TXT reloaded, then reset communication;
  mode 2 (warm reset): every object back to its default, DRIVEPAR.TXT, USER_PAR.TXT and SEQUENCE.TXT reloaded,
  the behaviour's `on_nmt_reset()`, then reset communication.
The boot-up message (0x700+n, one byte 0) is sent on entering PRE-OPERATIONAL when 0x2010 = 1, or always on a
device without 0x2010.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from pathlib import Path
from typing import Protocol

from servostudio.formats.sequence_model import LoadMode
from servostudio.od.model import ObjectDictionary, Value
from servostudio.sim.bus import VirtualBus
from servostudio.sim.clock import VirtualClock
from servostudio.sim.error_control import ErrorControl
from servostudio.sim.events import DriveEvents
from servostudio.sim.flash import DRIVEPAR, USER_PAR, FlashFiles
from servostudio.sim.frame import Frame
from servostudio.sim.nmt import HEARTBEAT_BASE, NMT_COB_ID, NmtCommand, NmtState
from servostudio.sim.objects import ObjectStore
from servostudio.sim.pdo import PdoEngine
from servostudio.sim.sdo_server import DEFAULT_RESPONSE_TIME, SdoServer
from servostudio.sim.sequences import SequenceMemory
from servostudio.sim.simulator_objects import with_simulator_objects

log = logging.getLogger(__name__)

SDO_REQUEST_BASE, SDO_RESPONSE_BASE = 0x600, 0x580
REDIRECTED_REQUEST_BASE, REDIRECTED_RESPONSE_BASE = 0x640, 0x5C0
SDO_TRAFFIC = (0x581, 0x67F)
"""COB-IDs reserved to default SDO channels (CiA 301 restricted identifiers, never a PDO)."""
COMMUNICATION_AREA = range(0x1000, 0x2000)
SYNC_COB_ID, SYNC_PERIOD = 0x1005, 0x1006
START_REMOTE_NODES = 0x2000
BOOT_UP_CONFIGURATION = 0x2010
RESET_CONFIGURATION = 0x205D
NETWORK_ERROR_BEHAVIOUR = 0x205E
GUARDING_ERROR_CODE = 51  # "Fieldbus guarding error" (node guarding or heartbeat), EMCY 0x8130


class Behaviour(Protocol):
    """What the node needs from a drive behaviour (servostudio.sim.drive implements it)."""

    def step(self, dt: float) -> None: ...
    def on_sync(self) -> None: ...
    def on_nmt_reset(self) -> None: ...
    def raise_error(self, code: int) -> None:
        """Latch drive error `code` (Infranor numbering): fault state, error objects, EMCY."""


BehaviourFactory = Callable[[ObjectStore, DriveEvents], Behaviour]


class SimulatedNode:
    def __init__(
        self,
        node_id: int,
        od: ObjectDictionary,
        clock: VirtualClock,
        bus: VirtualBus,
        behaviour_factory: BehaviourFactory,
        state_dir: Path | None = None,
        sdo_response_time: float = DEFAULT_RESPONSE_TIME,
    ) -> None:
        if not 1 <= node_id <= 127:
            raise ValueError(f"node ID must be 1..127, got {node_id}")
        self.node_id = node_id
        self.clock = clock
        self.bus = bus
        self.state = NmtState.INITIALISING
        self._sync_generation = 0
        self.store = ObjectStore(with_simulator_objects(od), node_id)
        self.events = DriveEvents(self.store, self.transmit, lambda: self.state.value, self._emcy_allowed)
        self.sequences = SequenceMemory.for_store(self.store)
        self.events.sequences = self.sequences
        self.flash = FlashFiles(
            self.store,
            clock,
            self.events,
            self._drive_error,
            None if state_dir is None else state_dir / f"node{node_id}",
            self.sequences,
        )
        self.pdo = PdoEngine(self.store, clock, self.transmit, lambda code: self.events.emergency(code))
        self.error_control = ErrorControl(self.store, clock, self.transmit, lambda: self.state, self._network_error)
        self.sdo = SdoServer(
            self.store, clock, SDO_RESPONSE_BASE + node_id, sdo_response_time, self.flash.confirmation_delay
        )
        self.redirected_sdo = (
            SdoServer(
                self.store, clock, REDIRECTED_RESPONSE_BASE + node_id, sdo_response_time, self.flash.confirmation_delay
            )
            if node_id < 64
            else None
        )
        self._sdo_request_ids = frozenset(self.sdo_request_ids())
        self._register_hooks()
        self._errors_before_boot: list[int] = []
        self.behaviour = behaviour_factory(self.store, self.events)
        self._load_flash_files()  # after the behaviour, so its hooks see the saved values as a "load" would
        bus.attach(self)
        clock.call_later(0.0, self._boot)

    def _load_flash_files(self) -> None:
        """Power-on values: DRIVEPAR.TXT, USER_PAR.TXT, and SEQUENCE.TXT into an emptied sequence memory."""
        self.flash.load(DRIVEPAR)
        self.flash.load(USER_PAR)
        if self.sequences is not None:
            self.sequences.records.clear()
            self.flash.load_sequences(LoadMode.LOAD, required=False)

    def _drive_error(self, code: int) -> None:
        """A stack-detected error (file, guarding) becomes a drive fault; while INITIALISING, once booted (so its
        EMCY can go out)."""
        if self.state is NmtState.INITIALISING:
            self._errors_before_boot.append(code)
        else:
            self.behaviour.raise_error(code)

    # -- identity / helpers ---------------------------------------------------------------------------------------

    def __repr__(self) -> str:
        return f"SimulatedNode({self.node_id}, {self.store.od.device!r}, {self.state.value})"

    def _value(self, index: int, sub: int = 0, default: int = 0) -> int:
        return int(self.store.get(index, sub)) if (index, sub) in self.store else default

    def transmit(self, frame: Frame) -> None:
        self.bus.transmit(frame, sender=self)

    def _emcy_allowed(self) -> bool:
        return self.state in (NmtState.PRE_OPERATIONAL, NmtState.OPERATIONAL)

    def _register_hooks(self) -> None:
        store = self.store
        self._read_sync_cob_id = store.integer_reader(SYNC_COB_ID, 0) if (SYNC_COB_ID, 0) in store else (lambda: 0x80)
        if (START_REMOTE_NODES, 0) in store:
            store.on_write(START_REMOTE_NODES, 0, self._start_remote_nodes)
        for index in (SYNC_COB_ID, SYNC_PERIOD):
            if (index, 0) in store:
                store.on_write(index, 0, lambda i, s, v: self.clock.call_later(0.0, self._restart_sync_producer))

    # -- time -----------------------------------------------------------------------------------------------------

    def step(self, dt: float) -> None:
        """One control period: the drive model, then the event-driven TPDOs it may have triggered."""
        self.behaviour.step(dt)
        self.pdo.poll()

    # -- reception ------------------------------------------------------------------------------------------------

    def receive(self, frame: Frame, timestamp: float) -> None:
        can_id = frame.can_id
        if frame.extended:
            return
        if SDO_TRAFFIC[0] <= can_id <= SDO_TRAFFIC[1] and can_id not in self._sdo_request_ids:
            return  # another node's SDO channel (COB-IDs no PDO may use): most frames of a busy bus
        if can_id == NMT_COB_ID:
            if len(frame.data) >= 2 and frame.data[1] in (0, self.node_id):
                self.nmt_command(frame.data[0])
            return
        if self.state is NmtState.INITIALISING:
            return
        if frame.rtr and can_id == HEARTBEAT_BASE + self.node_id:
            self.error_control.guard_request()
            return
        if HEARTBEAT_BASE < can_id <= HEARTBEAT_BASE + 127 and not frame.rtr:
            self.error_control.heartbeat_received(can_id - HEARTBEAT_BASE)
            return
        if self.state is NmtState.STOPPED:
            return
        if can_id == self._sync_id() and not frame.rtr:
            self._on_sync()
            return
        if not frame.rtr and self._serve_sdo(frame, self.transmit):
            return
        self.pdo.receive(frame)

    def handle_local(self, frame: Frame, reply: Callable[[Frame], None]) -> bool:
        """A frame from the serial link addressed to this drive's own SDO channels; False if it is not one."""
        if self.state in (NmtState.INITIALISING, NmtState.STOPPED):
            return frame.can_id in self.sdo_request_ids()
        return self._serve_sdo(frame, reply)

    def sdo_request_ids(self) -> tuple[int, ...]:
        ids = (SDO_REQUEST_BASE + self.node_id,)
        return ids + ((REDIRECTED_REQUEST_BASE + self.node_id,) if self.redirected_sdo else ())

    def _serve_sdo(self, frame: Frame, reply: Callable[[Frame], None]) -> bool:
        if frame.can_id == SDO_REQUEST_BASE + self.node_id:
            self.sdo.handle(frame.data, reply)
            return True
        if self.redirected_sdo is not None and frame.can_id == REDIRECTED_REQUEST_BASE + self.node_id:
            self.redirected_sdo.handle(frame.data, reply)
            return True
        return False

    # -- SYNC -----------------------------------------------------------------------------------------------------

    def _sync_id(self) -> int:
        """0x1005 bits 0–10 (read for every frame on the bus, so without the checked access)."""
        return self._read_sync_cob_id() & 0x7FF

    def consumes_sync(self, frame: Frame) -> bool:
        """Whether ``frame`` is this node's SYNC."""
        return not frame.rtr and not frame.extended and frame.can_id == self._sync_id()

    def cycle_period(self) -> float:
        """The communication cycle period 0x1006 (s) this node expects its SYNC at; 0 when none is configured or the
        node produces the SYNC itself (0x1005 bit 30)."""
        if self._value(SYNC_COB_ID) & 0x40000000:
            return 0.0
        return self._value(SYNC_PERIOD) * 1e-6

    def _on_sync(self) -> None:
        self.behaviour.on_sync()
        self.pdo.on_sync()

    def _restart_sync_producer(self) -> None:
        """0x1005 bit 30 makes this node the SYNC producer, with the period of 0x1006 (µs)."""
        self._sync_generation += 1
        generation = self._sync_generation
        period = self._value(SYNC_PERIOD) * 1e-6
        if self._value(SYNC_COB_ID) & 0x40000000 and period > 0:
            self.clock.call_later(period, lambda: self._produce_sync(generation, period))

    def _produce_sync(self, generation: int, period: float) -> None:
        if generation != self._sync_generation:
            return
        if self.state in (NmtState.PRE_OPERATIONAL, NmtState.OPERATIONAL):
            self.transmit(Frame(self._sync_id()))
            self._on_sync()  # a producer does not receive its own frame but follows its own SYNC
        self.clock.call_later(period, lambda: self._produce_sync(generation, period))

    # -- NMT ------------------------------------------------------------------------------------------------------

    def nmt_command(self, command: int) -> None:
        try:
            command = NmtCommand(command)
        except ValueError:
            return
        if command is NmtCommand.RESET_NODE:
            self._reset_node()
        elif command is NmtCommand.RESET_COMMUNICATION:
            self._reset_communication()
        elif self.state is not NmtState.INITIALISING:
            target = {
                NmtCommand.START: NmtState.OPERATIONAL,
                NmtCommand.STOP: NmtState.STOPPED,
                NmtCommand.ENTER_PRE_OPERATIONAL: NmtState.PRE_OPERATIONAL,
            }[command]
            self._enter(target)

    def _enter(self, state: NmtState) -> None:
        self.state = state
        self.pdo.set_active(state is NmtState.OPERATIONAL)

    def _boot(self) -> None:
        """INITIALISING -> PRE-OPERATIONAL, with the boot-up message when configured."""
        self._restart_sync_producer()
        self._enter(NmtState.PRE_OPERATIONAL)
        if self._value(BOOT_UP_CONFIGURATION, 0, 1) & 1:
            self.transmit(Frame(HEARTBEAT_BASE + self.node_id, b"\x00"))
        self.error_control.start()
        while self._errors_before_boot:
            self._drive_error(self._errors_before_boot.pop(0))

    def _reset_communication(self) -> None:
        self._enter(NmtState.INITIALISING)
        self.error_control.stop()
        self.sdo.reset()
        if self.redirected_sdo is not None:
            self.redirected_sdo.reset()
        self.store.restore_defaults(COMMUNICATION_AREA)
        self.flash.load(DRIVEPAR, only=COMMUNICATION_AREA)
        self.clock.call_later(0.0, self._boot)

    def _reset_node(self) -> None:
        mode = self._value(RESET_CONFIGURATION, 0, 2) & 0x0F
        if mode == 1:
            self.flash.load(DRIVEPAR)
        elif mode == 2:
            self.store.restore_defaults()
            self._load_flash_files()
            self.behaviour.on_nmt_reset()
        self._reset_communication()

    def _start_remote_nodes(self, index: int, sub: int, value: Value) -> None:
        """0x2000: 0 sends "enter pre-operational" to all nodes now, n sends "start" to all nodes after n ms."""
        delay_ms = int(value)
        command = NmtCommand.ENTER_PRE_OPERATIONAL if delay_ms == 0 else NmtCommand.START

        def send() -> None:
            self.transmit(Frame(NMT_COB_ID, bytes((command, 0))))
            self.nmt_command(command)  # the sender obeys its own broadcast

        self.clock.call_later(delay_ms * 1e-3, send)

    # -- errors ---------------------------------------------------------------------------------------------------

    def _network_error(self, what: str) -> None:
        """0x205E: 0 nothing, 1 drive error 51 (EMCY 0x8130 from the drive), 2 NMT Stopped."""
        behaviour = self._value(NETWORK_ERROR_BEHAVIOUR)
        log.info("node %d: %s lost (0x205E = %d)", self.node_id, what, behaviour)
        if behaviour == 1:
            self._drive_error(GUARDING_ERROR_CODE)
        elif behaviour == 2:
            self._enter(NmtState.STOPPED)
