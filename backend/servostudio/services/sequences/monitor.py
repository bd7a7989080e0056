"""The live monitor of a running program: sequence, phases, outputs, loop counter, captured position, and a timeline
of every executed sequence with its phases.

Sampling (docs/sequences.md, Live monitor): the monitor maps TPDO 4 event-driven (transmission type 255) with
**0x3605 first**, then 0x3601,2, 0x3602,1 and 0x3602,3.  The simulated drive (and the drive's event mode) sends an
event-driven TPDO in the very control period its first object changes; 0x3605 changes at every phase and whenever a
sequence begins (BEGIN starts it afresh at 1, waiting reads 0), so every executed sequence arrives — the same
number twice in a row too — stamped with the drive's time.  The one change that moves no phase, the program's end
(0x3601,2 back to −1), is read by SDO every ``POLL_PERIOD`` with the outputs (pulse outputs and the SEQ output's
minimum length end by time) and the captured position 0x360B.  The loop counter
is no object of the drive: the monitor counts it from the executed sequences by the sequencer's rule
(decisions.md §3) and the sequence table.
"""

from __future__ import annotations

import struct
import threading
import time
from dataclasses import dataclass, field

from servostudio.drive.access import Drive
from servostudio.drive.nmt import NMT_STATES
from servostudio.drive.sdo import SdoError
from servostudio.formats.sequence import SequenceTable
from servostudio.services.bus import BusConnection

#: the TPDO the monitor takes (the XtrapulsPac's TPDO 4 is unmapped by default); CiA 301 0x1800+n / 0x1A00+n
MONITOR_TPDO = 3
TPDO_COMMUNICATION, TPDO_MAPPING = 0x1800, 0x1A00
COB_ID_INVALID = 0x80000000
EVENT_DRIVEN = 255
MAPPED = ("sequence_phase", "sequence_executed", "sequence_outputs", "sequence_dedicated_outputs")
#: read by SDO: the end of a program moves no phase; pulse outputs and the SEQ output's minimum length end by time
POLLED = ("sequence_executed", "sequence_outputs", "sequence_dedicated_outputs", "sequence_captured_position")
PHASES = ("BEGIN", "CRUISE", "DECEL", "HOLD", "INPOS", "END")
END_BIT = 1 << 5
POLL_PERIOD = 0.1
TIMELINE_LIMIT = 10_000


def phase_name(sequence: int, phases: int) -> str:
    """The latest phase 0x3605 shows ("WAIT" for a sequence waiting for its start condition, "IDLE" for none)."""
    if sequence < 0:
        return "IDLE"
    if not phases:
        return "WAIT"
    return PHASES[min(phases.bit_length(), len(PHASES)) - 1]


@dataclass(frozen=True)
class Sample:
    t: float
    sequence: int
    phases: int

    def as_dict(self) -> dict[str, object]:
        return {"t": round(self.t, 4), "sequence": self.sequence, "phase": phase_name(self.sequence, self.phases)}


@dataclass
class LoopCount:
    """The sequencer's one loop counter, counted from the sequences the monitor saw end."""

    table: SequenceTable | None
    owner: int | None = None
    remaining: int = 0

    def ended(self, number: int) -> None:
        sequence = self.table.sequences.get(number) if self.table is not None else None
        count = sequence["SeqCount"] if sequence is not None else 0
        if not isinstance(count, int) or count == 0:
            return
        if self.owner != number:
            self.owner, self.remaining = number, count
        self.remaining -= 1
        if not self.remaining:
            self.owner = None

    def as_dict(self) -> dict[str, object] | None:
        return None if self.owner is None else {"sequence": self.owner, "remaining": self.remaining}


@dataclass
class MonitorState:
    sequence: int = -1
    phases: int = 0
    outputs: int = 0
    dedicated: int = 0
    captured: int | None = None
    timeline: list[Sample] = field(default_factory=list)
    runs: list[Sample] = field(default_factory=list)  # one per executed sequence: when it began, its last phase


class SequenceMonitor:
    """Watches one drive's sequencer until stopped; ``snapshot`` is what a client polls."""

    def __init__(self, connection: BusConnection, drive: Drive, table: SequenceTable | None = None) -> None:
        self.connection, self.drive = connection, drive
        self.state = MonitorState()
        self.counter = LoopCount(table)
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._started = time.monotonic()
        self._offset: float | None = None  # monotonic time − drive time, from the first TPDO
        self._tpdos = 0  # TPDOs received: a poll answer older than one of them is stale
        self._cob_id = 0
        self._thread = threading.Thread(target=self._poll, name=f"sequence-monitor {drive.node}", daemon=True)

    # ---- life ---------------------------------------------------------------------------------------------------

    def start(self) -> SequenceMonitor:
        """Map the TPDO, listen to it, put the node in OPERATIONAL (PDOs need it) and start polling."""
        self._cob_id = self._map_tpdo()
        self.connection.link.subscribe(self._cob_id, self._on_tpdo)
        if self.connection.nmt_state(self.drive.node) != NMT_STATES[0x05]:  # "OPERATIONAL", as heartbeats say
            self.connection.nmt("start", self.drive.node)
        self._poll_once()
        self._thread.start()
        return self

    def stop(self) -> None:
        self._stop.set()
        self.connection.link.unsubscribe(self._cob_id, self._on_tpdo)
        if self._thread.is_alive() and self._thread is not threading.current_thread():
            self._thread.join(timeout=2.0)

    def _map_tpdo(self) -> int:
        """CiA 301's order: invalidate the PDO, clear its mapping, map, count, transmission type, validate."""
        drive, communication, mapping = self.drive, TPDO_COMMUNICATION + MONITOR_TPDO, TPDO_MAPPING + MONITOR_TPDO
        cob_id = int(drive.read((communication, 1)).raw) & 0x7FF
        drive.write((communication, 1), cob_id | COB_ID_INVALID)
        drive.write((mapping, 0), 0)
        for position, name in enumerate(MAPPED, start=1):
            variable = drive.variable(name)
            drive.write((mapping, position), variable.index << 16 | variable.subindex << 8 | 16)
        drive.write((mapping, 0), len(MAPPED))
        drive.write((communication, 2), EVENT_DRIVEN)
        drive.write((communication, 1), cob_id)
        return cob_id

    # ---- samples ------------------------------------------------------------------------------------------------

    def _on_tpdo(self, cob_id: int, data: bytes, timestamp: float) -> None:
        """In the bus reader's thread: decode and record, nothing that waits."""
        if len(data) < 8:
            return
        phases, sequence, outputs, dedicated = struct.unpack_from("<HhHH", data)
        now = time.monotonic()
        if self._offset is None:
            self._offset = now - timestamp
        with self._lock:
            self._tpdos += 1
            self.state.outputs, self.state.dedicated = outputs, dedicated
            self._record(timestamp + self._offset - self._started, sequence, phases)

    def _poll(self) -> None:
        while not self._stop.wait(POLL_PERIOD):
            self._poll_once()

    def _poll_once(self) -> None:
        """The program's end (no phase moves then) and the captured position, by SDO; an answer that a TPDO overtook
        is dropped (it is older than what the TPDO said)."""
        with self._lock:
            seen = self._tpdos
        try:
            sequence, outputs, dedicated, captured = (int(self.drive.read(name).raw) for name in POLLED)
        except SdoError:
            return  # the next poll tries again; a lost link is the bus's to report
        with self._lock:
            self.state.captured = captured
            if self._tpdos != seen:
                return
            self.state.outputs, self.state.dedicated = outputs, dedicated
            if sequence != self.state.sequence:
                self._record(time.monotonic() - self._started, sequence, 0 if sequence >= 0 else self.state.phases)

    def _record(self, t: float, sequence: int, phases: int) -> None:
        """A new sample if anything moved; a new run when the number changes or the phases start afresh."""
        last = self.state.timeline[-1] if self.state.timeline else None
        if last is not None and (last.sequence, last.phases) == (sequence, phases):
            return
        fresh = last is None or sequence != last.sequence or (phases & last.phases) != last.phases
        if fresh and last is not None and last.sequence >= 0 and last.phases & END_BIT:
            self.counter.ended(last.sequence)
        self.state.sequence, self.state.phases = sequence, phases
        self.state.timeline.append(Sample(t, sequence, phases))
        del self.state.timeline[:-TIMELINE_LIMIT]
        if fresh and sequence >= 0:
            self.state.runs.append(Sample(t, sequence, phases))
            del self.state.runs[:-TIMELINE_LIMIT]
        elif sequence >= 0 and self.state.runs:
            self.state.runs[-1] = Sample(self.state.runs[-1].t, sequence, phases)

    # ---- what clients see ---------------------------------------------------------------------------------------

    def snapshot(self, since: int = 0) -> dict[str, object]:
        """The state now, the timeline samples from index ``since`` and every executed sequence so far."""
        with self._lock:
            state = self.state
            return {
                "now": round(time.monotonic() - self._started, 4),
                "running": state.sequence >= 0,
                "sequence": state.sequence,
                "phase": phase_name(state.sequence, state.phases),
                "phases": state.phases,
                "outputs": state.outputs,
                "dedicated_outputs": state.dedicated,
                "counter": self.counter.as_dict(),
                "captured_position": state.captured,
                "timeline": [sample.as_dict() for sample in state.timeline[since:]],
                "next": len(state.timeline),
                "executed": [run.as_dict() for run in state.runs],
            }

    def runs(self) -> list[Sample]:
        with self._lock:
            return list(self.state.runs)

    @property
    def running(self) -> bool:
        with self._lock:
            return self.state.sequence >= 0
