"""The XtrapulsPac's oscilloscope recorder: up to 4 channels sampled in the control period, with a level/edge trigger,
pre-trigger and re-arm, read back through the DOMAIN objects 0x5801 / 0x5841 (docs/eds.md §6, docs/scope.md).

The drive calls `sample()` at the end of each control period while `armed`, after that period's loops, physics
and measurements were updated: a record holds what a bus read (or a TPDO) would have returned at that instant. An
idle recorder costs the period one attribute test. The buffer objects change only when a recording completes, and
an SDO upload takes its bytes when it starts, so an upload interrupted by a link cut leaves nothing to clean up.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable
from enum import IntEnum
from typing import cast

from servostudio.od.model import Value
from servostudio.sim import sdo_abort
from servostudio.sim.drive.recording import (
    BUFFER,
    CHANNEL_SOURCE,
    CHANNELS,
    DEPTH,
    MULTIPLIER,
    PRE_TRIGGER,
    SINGLE,
    TRIGGER,
    TRIGGER_CONFIG,
    TRIGGER_SOURCE,
    Record,
    RecordingPlan,
    Trigger,
    pack_records,
    plan_recording,
    resolve_source,
)
from servostudio.sim.objects import ObjectStore
from servostudio.sim.sdo_abort import SdoAbort

OSC_DATA = 0x5801
RECORD_SIZE, RECORDING_COUNTER = 5, 6
CHANNEL_TYPE = 0x5810
CONTROL = 0x5828
STATUS = 0x5829
TRANSFER_CONFIG, FIRST_RECORD, RECORD_COUNT, TRIGGER_RECORD, RECORDS_AVAILABLE = 0x5840, 1, 2, 3, 4
TRANSFER = 0x5841
CONFIGURATION = (
    (BUFFER, DEPTH),
    (BUFFER, MULTIPLIER),
    (PRE_TRIGGER, 0),
    *((CHANNEL_SOURCE, channel) for channel in CHANNELS),
    *((TRIGGER_CONFIG, sub) for sub in (1, 2, 3, 4)),
    *((TRIGGER, sub) for sub in (1, 2)),
)
"""The objects a recording is planned from: written only while the recorder is not armed."""


class Status(IntEnum):
    """0x5829, PDO-mappable so that the tool can watch it."""

    IDLE = 0
    FILLING = 1
    WAITING = 2
    RECORDING = 3
    DONE = 4


_ARMED = (Status.FILLING, Status.WAITING, Status.RECORDING)


class Recorder:
    def __init__(self, store: ObjectStore) -> None:
        self.store = store
        self.status = Status.IDLE
        self.armed = False
        self._plan: RecordingPlan
        self._trigger: Trigger
        self._countdown = 0
        self._before: deque[Record] = deque()
        self._records: list[Record] = []
        self._trigger_index = 0
        self._previous: Value = 0
        self._has_previous = False
        self._waited = 0
        self._forced = False
        self._recorded_size = 1
        self._steps = {Status.FILLING: self._fill, Status.WAITING: self._wait, Status.RECORDING: self._record}
        self._take: Callable[[Record], None] = self._record
        self._register_hooks()

    @classmethod
    def for_store(cls, store: ObjectStore) -> Recorder | None:
        """The recorder of a drive whose dictionary has the oscilloscope objects (the XtrapulsPac), else None."""
        return cls(store) if (STATUS, 0) in store else None

    # -- objects --------------------------------------------------------------------------------------------------

    def _register_hooks(self) -> None:
        store = self.store
        for index, sub in CONFIGURATION:
            if (index, sub) in store:
                store.on_write(index, sub, self._refuse_while_armed)
        for channel in CHANNELS:
            store.on_write(CHANNEL_SOURCE, channel, self._channel_written)
        store.on_write(TRIGGER_CONFIG, TRIGGER_SOURCE, self._trigger_source_written)
        store.on_write(CONTROL, 0, self._command)
        store.on_read(TRANSFER, 0, self._selected_records)

    def _refuse_while_armed(self, index: int, sub: int, value: Value) -> None:
        """The recording in progress keeps the plan it was armed with; changing it needs a stop first."""
        if self.armed:
            reason = f"0x{index:04X},{sub}: the recorder is armed (stop it with 0x5828 = 0 first)"
            raise SdoAbort(sdo_abort.CANNOT_TRANSFER_STATE, reason)

    def _channel_written(self, index: int, sub: int, value: Value) -> None:
        """A channel source is checked; its data type code (0x5810,n) and the record size (0x5804,5) follow it."""
        pointer = int(value)
        self.store.set(CHANNEL_TYPE, sub, resolve_source(self.store, pointer).data_type.value if pointer else 0)
        sources = {channel: int(self.store.get(CHANNEL_SOURCE, channel)) for channel in CHANNELS} | {sub: pointer}
        self.store.set(BUFFER, RECORD_SIZE, sum((source & 0xFF) // 8 for source in sources.values()))

    def _trigger_source_written(self, index: int, sub: int, value: Value) -> None:
        """1..4 names a channel; anything else must be a source pointer the recorder can sample."""
        if int(value) not in CHANNELS:
            resolve_source(self.store, int(value))

    def _command(self, index: int, sub: int, value: Value) -> None:
        """0x5828: 0 stop, 1 arm, 2 force trigger (the range check has run before)."""
        (self.stop, self.arm, self.force)[int(value)]()

    def _selected_records(self, index: int, sub: int) -> bytes:
        """0x5841: records [first, first + count) of the last complete recording; count 0 = up to the last one."""
        data = cast(bytes, self.store.get(OSC_DATA, 0))
        size = self._recorded_size
        first = int(self.store.get(TRANSFER_CONFIG, FIRST_RECORD))
        count = int(self.store.get(TRANSFER_CONFIG, RECORD_COUNT))
        return data[first * size : len(data) if count == 0 else (first + count) * size]

    # -- commands -------------------------------------------------------------------------------------------------

    def arm(self) -> None:
        """A new recording planned from the objects as they are now (one in progress is dropped and restarts);
        its first record is taken at the end of the next control period."""
        self._plan = plan_recording(self.store)
        self._countdown = 1
        self._start()

    def stop(self) -> None:
        """Idle; a recording in progress is dropped, the last complete one stays readable."""
        self._enter(Status.IDLE)

    def force(self) -> None:
        """While filling or waiting, the next record becomes the trigger record; ignored otherwise."""
        self._forced = self.status in (Status.FILLING, Status.WAITING)

    def reset(self) -> None:
        """Warm reset: the node has put every object back to its default (so the recording is gone)."""
        self._enter(Status.IDLE)

    # -- recording ------------------------------------------------------------------------------------------------

    def sample(self) -> None:
        """End of a control period while armed: one record every `multiplier` periods."""
        self._countdown -= 1
        if self._countdown:
            return
        plan = self._plan
        self._countdown = plan.multiplier
        self._take(tuple([read() for read in plan.readers]))

    def _start(self) -> None:
        plan = self._plan
        self._before = deque(maxlen=plan.pre_trigger)
        self._records = []
        self._trigger_index = 0
        self._has_previous = self._forced = False
        self._waited = 0
        if plan.trigger is None:
            self._enter(Status.RECORDING)
            return
        self._trigger = plan.trigger
        self._enter(Status.FILLING if plan.pre_trigger else Status.WAITING)

    def _enter(self, status: Status) -> None:
        self.status = status
        self.armed = status in _ARMED
        if self.armed:
            self._take = self._steps[status]
        self.store.set(STATUS, 0, int(status))

    def _fill(self, record: Record) -> None:
        """Status 1: the first pre-trigger records; no edge is looked for before they are all there."""
        if self._forced:
            self._trigger_at(record)
            return
        self._keep(record, self._trigger.value_of(record))
        if len(self._before) == self._plan.pre_trigger:
            self._enter(Status.WAITING)

    def _wait(self, record: Record) -> None:
        """Status 2: the edge is tested between each record and the one before it; in auto mode the record taken
        when the timeout has passed since waiting began is the trigger record."""
        value = self._trigger.value_of(record)
        crossed = self._has_previous and self._trigger.fires(self._previous, value)
        self._waited += 1
        if crossed or self._forced or self._waited >= self._plan.auto_records:
            self._trigger_at(record)
            return
        self._keep(record, value)

    def _keep(self, record: Record, trigger_value: Value) -> None:
        """A record before the trigger: the ring keeps the newest pre-trigger ones."""
        self._before.append(record)
        self._previous = trigger_value
        self._has_previous = True

    def _trigger_at(self, record: Record) -> None:
        """`record` is time 0; it follows the pre-trigger records kept so far."""
        self._trigger_index = len(self._before)
        self._records = [*self._before, record]
        self._enter(Status.RECORDING)
        self._complete_if_full()

    def _record(self, record: Record) -> None:
        self._records.append(record)
        self._complete_if_full()

    def _complete_if_full(self) -> None:
        if len(self._records) >= self._plan.depth:
            self._complete()

    def _complete(self) -> None:
        """The buffer objects switch to the new recording at once; then done, or armed again (normal, auto)."""
        plan, store = self._plan, self.store
        store.set(OSC_DATA, 0, pack_records(plan.layout, self._records))
        store.set(TRANSFER_CONFIG, TRIGGER_RECORD, self._trigger_index)
        store.set(TRANSFER_CONFIG, RECORDS_AVAILABLE, len(self._records))
        store.set(BUFFER, RECORDING_COUNTER, (int(store.get(BUFFER, RECORDING_COUNTER)) + 1) & 0xFFFF)
        self._recorded_size = plan.layout.size
        if plan.rearm == SINGLE:
            self._enter(Status.DONE)
        else:
            self._start()
