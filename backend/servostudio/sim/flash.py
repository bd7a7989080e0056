"""The drive's flash files DRIVEPAR.TXT, USER_PAR.TXT and SEQUENCE.TXT, driven by the signatures written to
0x1010,1 / 0x1011,1.

Signatures are 4 ASCII characters read as a little-endian U32 (CiA 301: "save" = 0x65766173, "load" = 0x64616F6C);
XtrapulsPac adds "lusr" (apply USER_PAR.TXT), "sseq" (sequence memory -> SEQUENCE.TXT), "lseq" (SEQUENCE.TXT
replaces the sequence memory) and "mseq" (SEQUENCE.TXT merged into it). DRIVEPAR.TXT holds every object whose save
type is DRIVEPAR. While an operation runs (`OPERATION_TIME`) `events.flash_busy` is set, which the drive behaviour
shows as status word bit 15; with 0x205D bit 5 (save) / bit 4 (load) the SDO confirmation waits for the end of the
operation. Reading the signature object returns the procedure status of decisions.md §4 (0 never executed … 4 error,
5 done).

Files live in `<state dir>/node<N>/`; without a state directory they live in memory (they still survive an NMT
reset, not the end of the process). A file with an unknown object or an impossible value is refused as a whole
(nothing applied) and raises the drive error of the manual (42 drive parameters, 43 user parameters, 44
sequences; EMCY 0x6320).
Floating-point objects are stored as the integer of their IEEE bits, so the file format stays integer-only; a
text the format cannot carry (empty, or with leading/trailing spaces) is left out of the file.
"""

from __future__ import annotations

import logging
import struct
from collections.abc import Callable
from pathlib import Path

from servostudio.formats.objectfile import ObjectEntry, ObjectFileError, format_object_file, parse_object_file
from servostudio.formats.sequence_model import LoadMode
from servostudio.formats.sequence_reader import SequenceFileError, parse_sequence_text
from servostudio.formats.sequence_writer import format_sequence_table
from servostudio.formats.textfile import FILE_ENCODING, write_text_atomic
from servostudio.od.datatypes import DataType
from servostudio.od.model import SaveType, Value, Variable
from servostudio.sim import sdo_abort
from servostudio.sim.clock import VirtualClock
from servostudio.sim.events import DriveEvents
from servostudio.sim.objects import ObjectStore, check_range
from servostudio.sim.sdo_abort import SdoAbort
from servostudio.sim.sequences import SequenceMemory

log = logging.getLogger(__name__)

STORE_PARAMETERS = 0x1010
RESTORE_PARAMETERS = 0x1011
RESET_CONFIGURATION = 0x205D
DRIVEPAR = "DRIVEPAR.TXT"
USER_PAR = "USER_PAR.TXT"
SEQUENCE = "SEQUENCE.TXT"
OPERATION_TIME = 0.2
"""Virtual seconds a save or load keeps the drive busy."""


def signature(text: str) -> int:
    """ "save" -> 0x65766173: the four ASCII characters as a little-endian U32."""
    return int.from_bytes(text.encode("ascii"), "little")


SAVE, LOAD, LOAD_USER = signature("save"), signature("load"), signature("lusr")
SAVE_SEQUENCES, LOAD_SEQUENCES, MERGE_SEQUENCES = signature("sseq"), signature("lseq"), signature("mseq")

_FILE_ERRORS = {DRIVEPAR: 42, USER_PAR: 43, SEQUENCE: 44}


class ProcedureStatus:
    NEVER_EXECUTED, CANNOT_EXECUTE, RUNNING, ABORTED, ERROR, DONE = range(6)


class FlashFiles:
    def __init__(
        self,
        store: ObjectStore,
        clock: VirtualClock,
        events: DriveEvents,
        report_error: Callable[[int], None],
        directory: Path | None,
        sequences: SequenceMemory | None = None,
    ) -> None:
        self.store = store
        self.clock = clock
        self.events = events
        self._report_error = report_error
        self.sequences = sequences
        self.directory = directory
        self._memory: dict[str, str] = {}
        self._status = {STORE_PARAMETERS: ProcedureStatus.NEVER_EXECUTED, RESTORE_PARAMETERS: 0}
        self._busy_until = 0.0
        self.last_error = ""
        for index in (STORE_PARAMETERS, RESTORE_PARAMETERS):
            if (index, 1) in store:
                store.on_write(index, 1, self._signature_written)
                store.on_read(index, 1, lambda idx, sub: self._status[idx])

    # -- files ----------------------------------------------------------------------------------------------------

    def path(self, name: str) -> Path | None:
        return None if self.directory is None else self.directory / name

    def read_text(self, name: str) -> str | None:
        path = self.path(name)
        if path is None:
            return self._memory.get(name)
        return path.read_text(encoding=FILE_ENCODING) if path.exists() else None

    def write_text(self, name: str, text: str) -> None:
        path = self.path(name)
        if path is None:
            self._memory[name] = text
            return
        path.parent.mkdir(parents=True, exist_ok=True)
        write_text_atomic(path, text)

    # -- operations -----------------------------------------------------------------------------------------------

    def save(self) -> None:
        """Write every DRIVEPAR object's current value into DRIVEPAR.TXT."""
        entries = [
            ObjectEntry(var.index, var.subindex, _file_value(var, self.store.get(*var.key)))
            for var in self.store.od.variables()
            if var.save_type is SaveType.DRIVEPAR and not var.data_type.is_binary
        ]
        entries = [entry for entry in entries if _writable_entry(entry)]
        header = f"{DRIVEPAR} of node {self.store.node_id} ({self.store.od.device})"
        self.write_text(DRIVEPAR, format_object_file(entries, header))

    def load(self, name: str, only: range | None = None) -> bool:
        """Apply a file (all or nothing); False and a file error when it is missing values or malformed.

        `only` restricts the applied entries to an index range (power-on values of the communication objects).
        """
        text = self.read_text(name)
        if text is None:
            return name == DRIVEPAR  # no saved parameters yet: the defaults stay, as on a new drive
        try:
            entries = parse_object_file(text, name, self._problem)
        except ObjectFileError as exc:
            return self._failed(name, str(exc))
        applied: list[tuple[ObjectEntry, Value]] = []
        for entry in entries:
            if only is not None and entry.index not in only:
                continue
            try:
                applied.append((entry, self._apply(entry)))
            except SdoAbort as exc:
                return self._failed(name, f"{name}:{entry.line}: {exc}")
        self._undo_copies(applied)
        return True

    def _apply(self, entry: ObjectEntry) -> Value:
        """Write one entry as a bus write would (range checks, hooks); the value the store then holds."""
        var = self.store.od[(entry.index, entry.sub)]
        self.store.write_value(var, _object_value(var, entry.value))
        return self.store.get(entry.index, entry.sub)

    def _undo_copies(self, applied: list[tuple[ObjectEntry, Value]]) -> None:
        """Give back the file's value to every entry a later entry's write hook changed: a drive restores its saved
        image as saved. The copy rules model a user's write (XtrapulsPac motor data 0x6410,14-16 → the commutation
        0x3410, which `apha` may have set otherwise since), not the power-up."""
        for entry, value in applied:
            if self.store.get(entry.index, entry.sub) != value:
                self._apply(entry)

    def save_sequences(self) -> bool:
        """sseq: sequence memory -> SEQUENCE.TXT; error 44 when a slot cannot be written as a file."""
        try:
            text = format_sequence_table(self._sequence_memory().table(), f"{SEQUENCE} of node {self.store.node_id}")
        except ValueError as exc:
            return self._failed(SEQUENCE, str(exc))
        self.write_text(SEQUENCE, text)
        return True

    def load_sequences(self, mode: LoadMode, required: bool = True) -> bool:
        """lseq / mseq, and power-up (`required` False: no file, no sequences): SEQUENCE.TXT -> sequence memory,
        all or nothing (error 44)."""
        text = self.read_text(SEQUENCE)
        if text is None:
            return not required or self._failed(SEQUENCE, f"{SEQUENCE} does not exist")
        memory = self._sequence_memory()
        try:
            memory.take(parse_sequence_text(text, SEQUENCE, max_sequences=memory.capacity), mode)
        except (SequenceFileError, ValueError) as exc:
            return self._failed(SEQUENCE, str(exc))
        return True

    def _sequence_memory(self) -> SequenceMemory:
        """The sequence memory: the sequence operations are offered only on a device that has one."""
        if self.sequences is None:
            raise RuntimeError(f"node {self.store.node_id} has no sequence memory")
        return self.sequences

    def _failed(self, name: str, reason: str) -> bool:
        self.last_error = reason
        self._report_error(_FILE_ERRORS[name])
        return False

    def _problem(self, entry: ObjectEntry) -> str | None:
        var = self.store.od.get(entry.index, entry.sub)
        if var is None:
            return f"0x{entry.index:04X},{entry.sub} is not in the {self.store.od.device} dictionary"
        try:
            check_range(var, _object_value(var, entry.value))
        except (SdoAbort, ValueError, struct.error) as exc:
            return f"{var.label}: {exc}"
        return None

    # -- signatures -----------------------------------------------------------------------------------------------

    def _signature_written(self, index: int, sub: int, value: Value) -> None:
        operation = self._operations(index).get(int(value))
        if operation is None:
            return  # decisions.md §4: any other value is ignored
        self._status[index] = ProcedureStatus.RUNNING
        self.events.flash_busy = True
        try:
            ok = operation()
        except Exception as exc:  # the flash itself failed (state directory not writable, …): answer, never hang
            log.exception("flash operation 0x%08X on node %d failed", int(value), self.store.node_id)
            self.last_error = f"flash operation failed: {exc}"
            self._status[index] = ProcedureStatus.ERROR
            self.events.flash_busy = self.clock.now < self._busy_until
            raise SdoAbort(sdo_abort.CANNOT_TRANSFER, self.last_error) from exc
        self._busy_until = self.clock.now + OPERATION_TIME
        self.clock.call_at(self._busy_until, lambda: self._finish(index, ok))

    def _operations(self, index: int) -> dict[int, Callable[[], bool]]:
        if index == STORE_PARAMETERS:
            operations = {SAVE: self._save_ok}
            if self.sequences is not None:
                operations[SAVE_SEQUENCES] = self.save_sequences
            return operations
        operations = {LOAD: lambda: self.load(DRIVEPAR), LOAD_USER: lambda: self.load(USER_PAR)}
        if self.sequences is not None:
            operations[LOAD_SEQUENCES] = lambda: self.load_sequences(LoadMode.LOAD)
            operations[MERGE_SEQUENCES] = lambda: self.load_sequences(LoadMode.MERGE)
        return operations

    def _save_ok(self) -> bool:
        self.save()
        return True

    def _finish(self, index: int, ok: bool) -> None:
        self._status[index] = ProcedureStatus.DONE if ok else ProcedureStatus.ERROR
        if self.clock.now >= self._busy_until:
            self.events.flash_busy = False

    def confirmation_delay(self, index: int, sub: int) -> float:
        """Extra SDO response delay: to the end of the operation when 0x205D bit 5 (save) / bit 4 (load) asks so."""
        if index not in (STORE_PARAMETERS, RESTORE_PARAMETERS) or sub != 1 or not self.events.flash_busy:
            return 0.0
        config = int(self.store.get(RESET_CONFIGURATION, 0)) if (RESET_CONFIGURATION, 0) in self.store else 0
        bit = 0x20 if index == STORE_PARAMETERS else 0x10
        return max(0.0, self._busy_until - self.clock.now) if config & bit else 0.0


def _writable_entry(entry: ObjectEntry) -> bool:
    """The object file cannot carry an empty text or one with outer spaces: such a value is left out (default)."""
    try:
        format_object_file([entry])
    except ValueError:
        return False
    return True


def _file_value(var: Variable, value: Value) -> int | str:
    if var.data_type is DataType.REAL32:
        return struct.unpack("<I", struct.pack("<f", value))[0]
    if var.data_type is DataType.REAL64:
        return struct.unpack("<Q", struct.pack("<d", value))[0]
    return value if isinstance(value, str) else int(value)


def _object_value(var: Variable, value: int | str) -> Value:
    data_type = var.data_type
    if data_type.is_text:
        return str(value)
    if isinstance(value, str):
        raise ValueError(f"{data_type.name} needs a number, got {value!r}")
    if data_type is DataType.REAL32:
        return struct.unpack("<f", struct.pack("<I", value))[0]
    if data_type is DataType.REAL64:
        return struct.unpack("<d", struct.pack("<Q", value))[0]
    return value
