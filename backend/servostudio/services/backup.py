"""Backup and restore of drive parameters as the drive's own files (DRIVEPAR.TXT, USER_PAR.TXT, SEQUENCE.TXT).

Backup reads every object of the file's save type (``SaveType`` in the dictionary) — all reads of a drive are
queued at once, so the SDO engine keeps the drive busy back to back — and writes the object file atomically:
if the link fails, no file (or the previous file) is left, never half a file.  Objects the drive refuses
(abort) are left out and listed.

Restore first validates the whole file against the dictionary (syntax, object known, writable, type and range);
any error stops it with ``FILE:LINE: reason`` before anything is sent.  Then it writes every object, reads every
one back (objects that another write changed as a side effect are written once more), stores to flash with the
profile's signature, and reports per object.  A restore that fails part-way lists what was written; running it
again is safe (it writes the same values).

SEQUENCE.TXT goes through 0x3610 (select) / 0x3611 (26 parameters) with ``servostudio.formats.sequence``.
TTAPAR.TXT, a PROFIBUS drive's (TTA-PRO) E parameters, is the object file with ``PNU,IND`` addresses
(``servostudio.formats.parameterfile``, docs/profibus.md §10); it is backed up and restored the same way.
"""

from __future__ import annotations

import contextvars
import enum
import logging
import struct
import threading
import time
from collections.abc import Callable, Iterable
from concurrent.futures import CancelledError, Future, ThreadPoolExecutor, wait
from dataclasses import dataclass, field
from pathlib import Path
from typing import TypeVar

from servostudio.drive.access import Drive, DriveAccessError
from servostudio.drive.cia402 import State, decode_state
from servostudio.drive.object_values import ObjectValue
from servostudio.drive.profiles import DeviceProfile
from servostudio.drive.profiles.base import ProcedureAfterChange
from servostudio.drive.sdo import SAFETY_WAIT, SdoAbortError, SdoError, TransferBatch, settle
from servostudio.errors import CommunicationError, InvalidInput, RefusedForSafety, ServoStudioError
from servostudio.formats.objectfile import ObjectEntry, ObjectFileError
from servostudio.formats.parameterfile import format_drive_file, parse_drive_file
from servostudio.formats.sequence import SequenceFileError, SequenceTable, parse_sequence_text, write_sequence_file
from servostudio.formats.textfile import FILE_ENCODING, write_text_atomic
from servostudio.od.datatypes import DataType
from servostudio.od.model import ObjectDictionary, SaveType, Variable
from servostudio.services import sequence_buffer
from servostudio.services.cancel import Cancellation, Cancelled

log = logging.getLogger(__name__)
Progress = Callable[[dict[str, object]], None]
T = TypeVar("T")
SAVE_TIMEOUT = 10.0
_PROGRESS_STEPS = 20


class FileKind(enum.StrEnum):
    DRIVEPAR = "DRIVEPAR.TXT"
    USER_PAR = "USER_PAR.TXT"
    SEQUENCE = "SEQUENCE.TXT"
    TTAPAR = "TTAPAR.TXT"
    TTASEQ = "TTASEQ.TXT"

    @classmethod
    def from_path(cls, path: Path) -> FileKind:
        """The kind a file name says (case-insensitive, ``node3_DRIVEPAR.TXT`` too); DRIVEPAR otherwise."""
        name = path.name.upper()
        for kind in cls:
            if name.endswith((kind.value, kind.value.rsplit(".", 1)[0])):
                return kind
        return cls.DRIVEPAR

    @property
    def save_type(self) -> SaveType | None:
        return {
            FileKind.DRIVEPAR: SaveType.DRIVEPAR,
            FileKind.USER_PAR: SaveType.USER_PAR,
            FileKind.TTAPAR: SaveType.DRIVEPAR,
        }.get(self)


class BackupError(CommunicationError, RuntimeError):
    """A backup or restore that could not complete; nothing half-written is left behind."""


class BackupPlaceRefused(InvalidInput):
    """The folder a backup file goes to cannot be made (a file in the way, no permission)."""


class RestoreValidationError(InvalidInput, BackupError):
    """The file is invalid; nothing was sent to the drive.  The message is ``FILE:LINE: reason``."""


class DriveNotDisabled(RefusedForSafety, BackupError):
    """The device stores parameters only while disabled and the drive is enabled; nothing was written."""


@dataclass
class BackupResult:
    node: int
    file: str
    kind: str
    objects: int
    skipped: list[dict[str, str]] = field(default_factory=list)
    seconds: float = 0.0

    def as_dict(self) -> dict[str, object]:
        return {
            "node": self.node,
            "file": self.file,
            "kind": self.kind,
            "objects": self.objects,
            "skipped": self.skipped,
            "seconds": round(self.seconds, 3),
        }


@dataclass
class ObjectOutcome:
    label: str
    value: int | str
    status: str  # verified | failed | not written
    error: str = ""


@dataclass
class RestoreResult:
    node: int
    file: str
    kind: str
    outcomes: list[ObjectOutcome] = field(default_factory=list)
    stored: str = ""
    error: str = ""
    seconds: float = 0.0
    cancelled: bool = False

    @property
    def ok(self) -> bool:
        return not self.error and all(outcome.status == "verified" for outcome in self.outcomes)

    def as_dict(self) -> dict[str, object]:
        counts: dict[str, int] = {}
        for outcome in self.outcomes:
            counts[outcome.status] = counts.get(outcome.status, 0) + 1
        return {
            "node": self.node,
            "file": self.file,
            "kind": self.kind,
            "ok": self.ok,
            "counts": counts,
            "stored": self.stored,
            "error": self.error or None,
            "seconds": round(self.seconds, 3),
            "cancelled": self.cancelled,
            "objects": [outcome.__dict__ for outcome in self.outcomes if outcome.status != "verified"],
        }


# ---------------------------------------------------------------------------------------------------- backup --
def backup_objects(drive: Drive, save_type: SaveType) -> list[Variable]:
    """Objects of a save type that a restore can write back (readable and writable)."""
    return [
        var
        for var in _dictionary(drive).variables()
        if var.save_type is save_type
        and var.access.readable
        and var.access.writable
        and var.data_type not in (DataType.DOMAIN, DataType.OCTET_STRING)
    ]


def _dictionary(drive: Drive) -> ObjectDictionary:
    if drive.dictionary is None:
        raise BackupError(f"node {drive.node}: no object dictionary known for this drive; scan the bus first")
    return drive.dictionary


def _make_folder(folder: Path, what: str) -> None:
    """The folder a backup is written to, made before anything is read (a missing one is made, as ``DIR/node<N>/``
    is); refused with the reason — without the server's path — when it cannot be."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise BackupPlaceRefused(f"cannot make the folder for {what}: {error.strerror or error}") from None


def backup_file(
    drive: Drive,
    path: Path,
    kind: FileKind | None = None,
    progress: Progress | None = None,
    cancel: Cancellation | None = None,
) -> BackupResult:
    """Back up one file of one drive; the file is written atomically at the end (not at all when cancelled:
    raises Cancelled)."""
    kind = kind or FileKind.from_path(path)
    started = time.monotonic()
    _make_folder(path.parent, path.name)
    if cancel is not None:
        cancel.check(f"{kind.value} of node {drive.node} was read")
    if kind is FileKind.SEQUENCE:
        table = _read_sequences(drive, progress)
        write_sequence_file(path, table, header=_header(drive, kind))
        return BackupResult(drive.node, str(path), kind.value, len(table), seconds=time.monotonic() - started)
    if kind is FileKind.TTASEQ:
        count = _back_up_sequence_buffer(drive, path, progress)
        return BackupResult(drive.node, str(path), kind.value, count, seconds=time.monotonic() - started)
    assert kind.save_type is not None  # every other file holds objects of one save type
    variables = backup_objects(drive, kind.save_type)
    values, skipped = _read_all(drive, variables, kind, progress, cancel)
    entries = []
    for value in values:
        file_value = _file_value(value)
        if isinstance(file_value, str) and _unwritable_text(file_value):
            skipped.append(
                {
                    "object": value.variable.label,
                    "reason": f"text {file_value!r} has no object-file syntax "
                    "(empty, padded, numeric-looking or with ';')",
                }
            )
            continue
        entries.append(ObjectEntry(value.variable.index, value.variable.subindex, file_value))
    write_text_atomic(path, format_drive_file(kind.value, entries, header=_header(drive, kind)))
    return BackupResult(drive.node, str(path), kind.value, len(entries), skipped, time.monotonic() - started)


def _read_all(
    drive: Drive,
    variables: list[Variable],
    kind: FileKind,
    progress: Progress | None,
    cancel: Cancellation | None = None,
) -> tuple[list[ObjectValue], list[dict[str, str]]]:
    """Read every object in one batch (the engine sends them back to back); this thread waits once, and a
    cancellation drops the reads not yet sent."""
    reporter = _Reporter(progress, "backup", drive.node, kind.value, len(variables))
    outcomes = _wait_batch(drive.submit_read_all(variables, on_each=lambda position, outcome: reporter.step()), cancel)
    if cancel is not None and cancel.requested:
        raise Cancelled(f"backup of node {drive.node} ({kind.value}) cancelled, no file written")
    values: list[ObjectValue] = []
    skipped: list[dict[str, str]] = []
    for var, outcome in zip(variables, outcomes, strict=True):
        if isinstance(outcome, SdoAbortError):
            skipped.append({"object": var.label, "reason": outcome.reason})
        elif isinstance(outcome, SdoError):
            raise BackupError(f"backup of node {drive.node} ({kind.value}) stopped, no file written: {outcome}")
        elif isinstance(outcome, ValueError):  # the drive answered bytes that are no value of the object's type
            skipped.append({"object": var.label, "reason": str(outcome)})
        elif isinstance(outcome, Exception):
            raise outcome
        else:
            values.append(outcome)
    return values, skipped


def _wait_all(futures: list[Future], reporter: _Reporter) -> None:
    """Wait once for all transfers (a sequence file's mixed writes and reads), counting progress as they complete.

    Waiting on each future in turn would wake this thread once per object, competing with the bus reader for
    the interpreter on every answer; here only the reader thread runs until the last answer.
    """
    for future in futures:
        future.add_done_callback(reporter.step_done)
    wait(futures, SAFETY_WAIT)


def _file_value(value: ObjectValue) -> int | str:
    """Object-file spelling: integers as they are, REAL32/64 as their IEEE-754 bit pattern, text as text."""
    raw = value.raw
    if isinstance(raw, float):
        fmt = "<f" if value.variable.data_type is DataType.REAL32 else "<d"
        return int.from_bytes(struct.pack(fmt, raw), "little")
    if isinstance(raw, str):
        return raw.rstrip("\0")
    if isinstance(raw, bytes):  # backup_objects leaves DOMAIN and OCTET_STRING out
        raise BackupError(f"{value.variable.label}: a binary value has no object-file form")
    return raw


def _unwritable_text(text: str) -> bool:
    """The object file cannot spell empty or padded text, text that starts like a number, or ';' and line breaks."""
    return not text or text != text.strip() or text[0] in "+-0123456789" or any(char in text for char in ";\r\n")


def _header(drive: Drive, kind: FileKind) -> str:
    stamp = time.strftime("%Y-%m-%d %H:%M:%S")
    return f"{kind.value} of node {drive.node} ({_device_name(drive)}), Servo Studio backup {stamp}"


def _device_name(drive: Drive) -> str:
    """The product as its dictionary names it (``TTA-PRO``), else the profile's key."""
    return drive.dictionary.product_name if drive.dictionary else drive.profile.device


def backup_drive(
    drive: Drive,
    directory: Path,
    kinds: Iterable[FileKind] | None = None,
    progress: Progress | None = None,
    cancel: Cancellation | None = None,
) -> list[BackupResult]:
    """All backup files of a drive into ``directory`` (the profile's parameter files, plus SEQUENCE.TXT).

    When cancelled, the files completed so far are returned (``cancel.requested`` tells the caller)."""
    _make_folder(directory, "the backup")
    results = []
    for kind in kinds or drive_file_kinds(drive):
        try:
            results.append(backup_file(drive, directory / kind.value, kind, progress, cancel))
        except Cancelled:
            break
    return results


def restore_drive(
    drive: Drive,
    directory: Path,
    kinds: Iterable[FileKind] | None = None,
    progress: Progress | None = None,
    store: bool = True,
    cancel: Cancellation | None = None,
) -> list[RestoreResult]:
    """Restore the backup files of a drive from ``directory`` (by default every file of the drive found there).

    Files not started when a cancellation comes are left out of the result."""
    chosen = list(kinds or [kind for kind in drive_file_kinds(drive) if (directory / kind.value).is_file()])
    if not chosen:
        raise no_files(drive.node, drive_file_kinds(drive))
    results = []
    for kind in chosen:
        if cancel is not None and cancel.requested:
            break
        results.append(restore_file(drive, directory / kind.value, kind, progress, store, cancel))
    return results


def no_files(node: int, kinds: Iterable[FileKind]) -> RestoreValidationError:
    """A restore of a folder without any of the device's files: the refusal names the files it looked for."""
    names = ", ".join(kind.value for kind in kinds)
    return RestoreValidationError(f"node{node}/: none of {names} for node {node}")


def drive_file_kinds(drive: Drive) -> list[FileKind]:
    return profile_file_kinds(drive.profile)


def profile_file_kinds(profile: DeviceProfile) -> list[FileKind]:
    """The files a backup of this device holds (a client of the server knows the device, not the drive)."""
    kinds = [FileKind(name) for name in profile.parameter_files]
    if profile.has_sequences and profile.has("sequence_parameters"):
        kinds.append(FileKind.SEQUENCE)
    if profile.sequence_buffer is not None:
        kinds.append(FileKind(profile.sequence_buffer.file))
    return kinds


def run_per_drive(drives: list[Drive], work: Callable[[Drive], T]) -> dict[int, T | Exception]:
    """Run ``work`` on every drive in parallel; the result per node is its value or the exception it raised."""
    results: dict[int, T | Exception] = {}
    with ThreadPoolExecutor(max_workers=max(1, len(drives)), thread_name_prefix="per-drive") as pool:
        # each drive's thread acts for the caller (motion guard, audit log): a copy of its context apiece
        futures = {drive.node: pool.submit(contextvars.copy_context().run, work, drive) for drive in drives}
        for node, future in futures.items():
            try:
                results[node] = future.result()  # the work bounds each of its own waits (`settle`)
            except Exception as error:  # reported per drive, the others go on; a bug is logged as well
                if not isinstance(error, ServoStudioError):
                    log.exception("node %d: unexpected failure", node)
                results[node] = error
    return results


# --------------------------------------------------------------------------------------------------- restore --
def validate_object_text(
    drive: Drive, text: str, name: str, kind: FileKind = FileKind.DRIVEPAR
) -> list[tuple[ObjectEntry, Variable, bytes]]:
    """Parse and check a whole object file (``name`` as messages call it; TTAPAR.TXT in its own syntax); raise
    RestoreValidationError (``NAME:LINE: reason``) on the first problem."""
    checked: list[tuple[ObjectEntry, Variable, bytes]] = []

    def validate(entry: ObjectEntry) -> str | None:
        try:
            variable = drive.variable((entry.index, entry.sub))
            value = _entry_value(variable, entry.value)
            variable, _, data = drive.prepare_write(variable, value)
        except (DriveAccessError, ValueError) as error:
            return str(error).removeprefix(f"node {drive.node}: ")
        checked.append((entry, variable, data))
        return None

    try:
        parse_drive_file(kind.value, text, name, validate)
    except ObjectFileError as error:
        raise RestoreValidationError(f"{error} — nothing was written to node {drive.node}") from None
    return checked


def _entry_value(variable: Variable, value: int | str) -> int | float | str:
    if variable.data_type.is_float and isinstance(value, int):
        fmt, size = ("<f", 4) if variable.data_type is DataType.REAL32 else ("<d", 8)
        if not 0 <= value < 1 << (8 * size):
            raise ValueError(f"{variable.label}: {value} is not a {variable.data_type.name} bit pattern")
        return struct.unpack(fmt, value.to_bytes(size, "little"))[0]
    if variable.data_type.is_text and isinstance(value, int):
        return str(value)
    return value


def restore_file(
    drive: Drive,
    path: Path,
    kind: FileKind | None = None,
    progress: Progress | None = None,
    store: bool = True,
    cancel: Cancellation | None = None,
) -> RestoreResult:
    """Validate, write, verify and store one file of the server's disk to one drive (see `restore_text`)."""
    kind = kind or FileKind.from_path(path)
    try:
        text = path.read_text(encoding=FILE_ENCODING)
    except OSError as error:
        raise RestoreValidationError(
            f"{path.name}: {error.strerror} — nothing was written to node {drive.node}"
        ) from None
    return restore_text(drive, text, kind, progress, store, cancel, file=str(path))


def restore_text(
    drive: Drive,
    text: str,
    kind: FileKind,
    progress: Progress | None = None,
    store: bool = True,
    cancel: Cancellation | None = None,
    file: str | None = None,
) -> RestoreResult:
    """Validate, write, verify and store one drive file's text (an upload; any text: every byte is Latin-1, and an
    empty file writes nothing) to one drive.  Messages name the file by its own name or, for an upload, its kind
    (``DRIVEPAR.TXT:3: …``), never by a server path; ``file`` is what the result reports as its source (default: the
    kind).

    A cancellation drops the writes not yet sent: the result lists which objects were written (not verified, not
    stored).  A sequence file is written whole once started (half a sequence memory is worth nothing)."""
    started = time.monotonic()
    result = RestoreResult(drive.node, file or kind.value, kind.value)
    if kind is FileKind.TTASEQ:
        return _restore_sequence_buffer(drive, text, Path(file).name if file else kind.value, result, progress, cancel)
    if kind is FileKind.SEQUENCE:
        table, writes = _validated_sequence_writes(drive, text)
    else:
        checked = validate_object_text(drive, text, Path(file).name if file else kind.value, kind)
        writes = _in_restore_order(drive, [(var, _entry_value(var, entry.value)) for entry, var, _ in checked])
    _check_can_store(drive, store)
    if cancel is not None and cancel.requested:
        result.outcomes = [ObjectOutcome(var.label, _shown(value), "not written") for var, value in writes]
        result.error, result.cancelled = (
            (
                f"restore of node {drive.node} cancelled: 0 of {len(writes)} objects were "
                "written; nothing was stored to flash"
            ),
            True,
        )
        return result
    try:
        if kind is FileKind.SEQUENCE:
            result.outcomes = _write_sequences(drive, table, writes, progress)
        else:
            _write_with_procedures(drive, writes, kind, progress, result.outcomes, cancel)
        if store and all(outcome.status == "verified" for outcome in result.outcomes):
            procedure = "save_sequences" if kind is FileKind.SEQUENCE else "save"
            drive.start_procedure(procedure, timeout=SAVE_TIMEOUT)
            result.stored = procedure
    except (SdoError, BackupError) as error:
        result.error = str(error)
    except Cancelled as error:
        result.error, result.cancelled = str(error), True
    result.seconds = time.monotonic() - started
    return result


def _in_restore_order(drive: Drive, writes: list[tuple[Variable, object]]) -> list[tuple[Variable, object]]:
    """The profile's ``restore_first`` objects ahead, in its order (what the others are scaled by must be in place
    before them, the TTA-PRO's 721 and 740/870), the rest in the file's order."""
    first = [drive.profile.address(name) for name in drive.profile.restore_first]
    return sorted(writes, key=lambda write: _rank(first, write[0].key))


def _rank(first: list[tuple[int, int]], address: tuple[int, int]) -> int:
    return first.index(address) if address in first else len(first)


def _write_with_procedures(
    drive: Drive,
    writes: list[tuple[Variable, object]],
    kind: FileKind,
    progress: Progress | None,
    report: list[ObjectOutcome],
    cancel: Cancellation | None,
) -> None:
    """Write and verify the file's objects; a procedure the profile needs after a change (the TTA-PRO's feedback
    programming, PNU 894, after 890-893/898) runs right after its objects — only when this restore changes one of
    them against what the drive held before, and they all verified — and the rest of the file follows."""
    due = [after for after in drive.profile.procedures_after_change if _changes(drive, writes, after)]
    split = max((_after_last(drive, writes, after) for after in due), default=len(writes))
    _write_and_verify(drive, writes[:split], kind, progress, report, cancel)
    if due and all(outcome.status == "verified" for outcome in report):
        for after in due:
            _run_after_change(drive, after)
    if writes[split:]:
        _write_and_verify(drive, writes[split:], kind, progress, report, cancel)


def _procedure_addresses(drive: Drive, after: ProcedureAfterChange) -> set[tuple[int, int]]:
    return {drive.profile.address(name) for name in after.objects}


def _changes(drive: Drive, writes: list[tuple[Variable, object]], after: ProcedureAfterChange) -> bool:
    """The file sets one of the procedure's objects to a value the drive does not hold now (read before writing)."""
    addresses = _procedure_addresses(drive, after)
    return any(var.key in addresses and not _same(drive.read(var).raw, value) for var, value in writes)


def _after_last(drive: Drive, writes: list[tuple[Variable, object]], after: ProcedureAfterChange) -> int:
    addresses = _procedure_addresses(drive, after)
    return 1 + max(position for position, (var, _) in enumerate(writes) if var.key in addresses)


def _run_after_change(drive: Drive, after: ProcedureAfterChange) -> None:
    try:
        drive.start_procedure(after.procedure, timeout=after.timeout)
    except SdoError as error:
        raise BackupError(
            f"restore of node {drive.node} stopped: {after.procedure} after {', '.join(after.objects)} failed: "
            f"{error}; the rest of the file was not written, nothing was stored to flash"
        ) from None


def store_parameters(drive: Drive) -> dict[str, object]:
    """Store the values the drive holds now in its non-volatile memory, so that they survive a power cycle: the
    profile's ``save`` procedure (0x1010,1 = 'save' on the CANopen drives, PNU 729 = 1 on a TTA-PRO).  A device that
    saves only while disabled is refused enabled, before anything is written."""
    started = time.monotonic()
    action = store_action(drive.profile, _dictionary(drive))
    _check_can_store(drive, True)
    drive.start_procedure("save", timeout=SAVE_TIMEOUT)
    return {"node": drive.node, "stored": "save", "wrote": action, "seconds": round(time.monotonic() - started, 3)}


def store_action(profile: DeviceProfile, od: ObjectDictionary) -> str:
    """What storing writes on a device, in its dictionary's words (``PNU 729 Save parameters = 1``,
    ``0x1010,1 Store parameters.… = 'save'``): the UI says it before the click, the result after it."""
    address, value = profile.signature("save")
    signature = None if "save" in profile.procedure_values else profile.signatures.get("save")
    return f"{od[address].label} = {repr(signature[1]) if signature else value}"


def _check_can_store(drive: Drive, store: bool) -> None:
    if store and drive.profile.save_needs_disabled:
        state = decode_state(int(drive.read("statusword").raw))
        if state is State.OPERATION_ENABLED:
            raise DriveNotDisabled(
                f"node {drive.node}: {_device_name(drive)} stores parameters only with the drive "
                "disabled; disable it first — nothing was written"
            )


def _write_and_verify(
    drive: Drive,
    writes: list[tuple[Variable, object]],
    kind: FileKind,
    progress: Progress | None,
    report: list[ObjectOutcome],
    cancel: Cancellation | None = None,
) -> None:
    """Write all, read all back; rewrite what a later write changed (side effects), read back once more.

    ``report`` receives one outcome per object up front and is updated as answers arrive, so after a failure it
    says exactly which objects were written.
    """
    outcomes = {
        index: ObjectOutcome(var.label, _shown(value), "not written") for index, (var, value) in enumerate(writes)
    }
    report.extend(outcomes.values())
    reporter = _Reporter(progress, "restore", drive.node, kind.value, 2 * len(writes))
    pending = list(range(len(writes)))
    for _ in range(2):  # one rewrite pass for values that a later write changed
        written = _wait_batch(
            drive.submit_write_all(
                [writes[index] for index in pending], on_each=lambda position, outcome: reporter.step()
            ),
            cancel,
        )
        link_error: SdoError | None = None
        for index, outcome in zip(pending, written, strict=True):
            if isinstance(outcome, CancelledError):
                continue  # dropped (cancelled, or the drive stopped answering) before it was sent: "not written"
            if isinstance(outcome, SdoAbortError):
                outcomes[index].status, outcomes[index].error = "failed", outcome.reason
            elif isinstance(outcome, SdoError):
                link_error = link_error or outcome
            elif isinstance(outcome, Exception):
                raise outcome
            else:
                outcomes[index].status, outcomes[index].error = "written", ""
        if link_error is not None:
            raise _partial(drive, outcomes, link_error)
        if cancel is not None and cancel.requested:
            raise _cancelled(drive, outcomes)
        readable = [
            index for index in pending if outcomes[index].status == "written" and writes[index][0].access.readable
        ]
        read_back = _wait_batch(
            drive.submit_read_all(
                [writes[index][0] for index in readable], on_each=lambda position, outcome: reporter.step()
            ),
            cancel,
        )
        mismatched = []
        for index, outcome in zip(readable, read_back, strict=True):
            if isinstance(outcome, CancelledError):
                continue
            if isinstance(outcome, SdoAbortError):
                outcomes[index].status, outcomes[index].error = "failed", f"read back: {outcome.reason}"
            elif isinstance(outcome, SdoError):
                raise _partial(drive, outcomes, outcome)
            elif isinstance(outcome, ValueError):  # bytes that are no value of the object's type
                outcomes[index].status, outcomes[index].error = "failed", f"read back: {outcome}"
            elif isinstance(outcome, Exception):
                raise outcome
            elif _same(outcome.raw, writes[index][1]):
                outcomes[index].status = "verified"
            else:
                outcomes[index].status, outcomes[index].error = "failed", f"read back {_shown(outcome.raw)}"
                mismatched.append(index)
        if cancel is not None and cancel.requested:
            raise _cancelled(drive, outcomes)
        for index in pending:
            if outcomes[index].status == "written":  # write-only objects cannot be read back
                outcomes[index].status = "verified"
        pending = mismatched
        if not pending:
            break


def _wait_batch(batch: TransferBatch[T], cancel: Cancellation | None) -> list[T | Exception]:
    """The outcomes of a batch; a cancellation meanwhile drops its transfers not yet sent."""
    forget = cancel.on_cancel(batch.cancel) if cancel is not None else None
    try:
        return batch.outcomes()
    finally:
        if forget is not None:
            forget()


def _partial(drive: Drive, outcomes: dict[int, ObjectOutcome], error: SdoError) -> BackupError:
    written = [outcome.label for outcome in outcomes.values() if outcome.status in ("written", "verified")]
    return BackupError(
        f"restore of node {drive.node} stopped: {error}. {len(written)} of {len(outcomes)} objects "
        "had been written; nothing was stored to flash. Run the restore again once the link is back."
    )


def _cancelled(drive: Drive, outcomes: dict[int, ObjectOutcome]) -> Cancelled:
    sent = [outcome for outcome in outcomes.values() if outcome.status != "not written"]
    refused = [outcome for outcome in sent if outcome.status == "failed" and not outcome.error.startswith("read back")]
    return Cancelled(
        f"restore of node {drive.node} cancelled: {len(sent) - len(refused)} of {len(outcomes)} "
        f"objects were written ({len(refused)} refused, the rest not sent); nothing was stored to flash"
    )


def _same(read: object, written: object) -> bool:
    """The value read back is the one written (a REAL to its precision, text without the drive's NUL padding)."""
    floats = isinstance(read, float) or isinstance(written, float)
    if floats and isinstance(read, int | float) and isinstance(written, int | float):
        return abs(read - written) <= 1e-6 * max(1.0, abs(written))
    if isinstance(read, str) and isinstance(written, str):
        return read.rstrip("\0") == written
    return read == written


def _shown(value: object) -> int | str:
    return value if isinstance(value, (int, str)) else str(value)


# ------------------------------------------------------------------------------------------------- sequences --
def _read_sequences(drive: Drive, progress: Progress | None) -> SequenceTable:
    count = int(drive.read("max_sequences").raw)
    number_var, type_var = drive.variable("sequence_number"), drive.variable((0x3611, 1))
    reporter = _Reporter(progress, "backup", drive.node, FileKind.SEQUENCE.value, count)
    types: dict[int, Future] = {}
    for number in range(count):  # per-node FIFO (bulk lane): each read sees the number selected just before it
        drive.submit_write(number_var, number, bulk=True)
        types[number] = drive.submit_read(type_var, bulk=True)
    records: dict[int, dict[int, Future]] = {}
    assert drive.dictionary is not None  # drive.variable above refused a drive without one
    try:
        used = [number for number, future in types.items() if settle(future).raw != 0]
        subs = sorted(sub for sub in drive.dictionary.object(0x3611).subs if sub >= 1)
        for number in used:
            drive.submit_write(number_var, number, bulk=True)
            records[number] = {sub: drive.submit_read(drive.variable((0x3611, sub)), bulk=True) for sub in subs}
        values = {
            number: {sub: int(settle(future).raw) for sub, future in record.items()}
            for number, record in records.items()
        }
    except SdoError as error:
        raise BackupError(f"backup of node {drive.node} (SEQUENCE.TXT) stopped, no file written: {error}") from None
    reporter.finish()
    try:
        return SequenceTable.from_object_values(values)
    except ValueError as error:
        raise BackupError(f"node {drive.node}: {error}") from None


def _validated_sequence_writes(drive: Drive, text: str) -> tuple[SequenceTable, list[tuple[Variable, object]]]:
    count = int(drive.read("max_sequences").raw)
    name = FileKind.SEQUENCE.value
    try:
        table = parse_sequence_text(text, name, max_sequences=count)
    except SequenceFileError as error:
        raise RestoreValidationError(f"{error} — nothing was written to node {drive.node}") from None
    writes: list[tuple[Variable, object]] = []
    for write in table.to_object_writes(clear_below=count):
        try:
            variable, raw, _ = drive.prepare_write((write.index, write.sub), write.value)
        except DriveAccessError as error:
            raise RestoreValidationError(f"{name}: {error} — nothing was written") from None
        writes.append((variable, raw))
    return table, writes


def _write_sequences(
    drive: Drive, table: SequenceTable, writes: list[tuple[Variable, object]], progress: Progress | None
) -> list[ObjectOutcome]:
    """Write the whole sequence memory (LOAD semantics), then read it back and compare sequence by sequence."""
    futures = [drive.submit_write(variable, value, bulk=True) for variable, value in writes]
    reporter = _Reporter(progress, "restore", drive.node, FileKind.SEQUENCE.value, len(futures))
    _wait_all(futures, reporter)
    for future in futures:
        try:
            settle(future, 0)  # _wait_all waited already: each is done, or overdue
        except SdoAbortError as error:
            raise BackupError(f"node {drive.node}: sequence memory refused a write: {error}") from None
    memory = _read_sequences(drive, None)
    outcomes = []
    for number in sorted(set(table) | set(memory)):
        wanted, found = table.sequences.get(number), memory.sequences.get(number)
        status = "verified" if wanted == found else "failed"
        held = found.type.name if found else "empty"
        outcomes.append(
            ObjectOutcome(
                f"sequence {number}",
                wanted.type.name if wanted else "empty",
                status,
                "" if status == "verified" else f"drive holds {held}",
            )
        )
    return outcomes


# ------------------------------------------------------------------------------- sequences behind a buffer --
def _back_up_sequence_buffer(drive: Drive, path: Path, progress: Progress | None) -> int:
    """TTASEQ.TXT: the sequences in use, read through the drive's buffer; the number of sequences."""
    buffer = sequence_buffer.buffer_of(drive)
    reporter = _Reporter(progress, "backup", drive.node, buffer.file, buffer.count)
    try:
        table = sequence_buffer.read_table(drive, reporter.step)
    except SdoError as error:
        raise BackupError(f"backup of node {drive.node} ({buffer.file}) stopped, no file written: {error}") from None
    reporter.finish()
    write_text_atomic(path, sequence_buffer.format_table(drive.profile, table, _header(drive, FileKind(buffer.file))))
    return len(table)


def _restore_sequence_buffer(
    drive: Drive, text: str, name: str, result: RestoreResult, progress: Progress | None, cancel: Cancellation | None
) -> RestoreResult:
    """Validate the whole file, then write the whole table (the sequences not listed are cleared), verify it, and
    store the checksum — only once every sequence verified: a table left half-written keeps the old checksum, so
    the drive reports it (an EEPROM sequence checksum fault) at its next power-up instead of running it."""
    started = time.monotonic()
    try:
        table = sequence_buffer.parse_table(drive.profile, _dictionary(drive), text, name)
    except sequence_buffer.SequenceTableInvalid as error:
        raise RestoreValidationError(f"{error} — nothing was written to node {drive.node}") from None
    _check_can_store(drive, True)
    if cancel is not None and cancel.requested:
        result.error, result.cancelled = f"restore of node {drive.node} cancelled: nothing was written", True
        return result
    reporter = _Reporter(progress, "restore", drive.node, result.kind, sequence_buffer.buffer_of(drive).count)
    try:
        held = sequence_buffer.write_table(drive, table, reporter.step)
    except SdoError as error:
        result.error = f"restore of node {drive.node} stopped: {error}. {_UNCHECKED}"
    else:
        result.outcomes = _sequence_outcomes(table, held)
        differ = sum(1 for difference in held.values() if difference)
        if differ:
            result.error = f"node {drive.node}: {differ} sequences differ from the file. {_UNCHECKED}"
        else:
            result.stored = sequence_buffer.store_checksum(drive)
    result.seconds = time.monotonic() - started
    return result


_UNCHECKED = (
    "The sequence checksum was not updated: the drive reports an EEPROM sequence checksum fault at its next "
    "power-up until a restore of the table completes."
)


def _sequence_outcomes(table: sequence_buffer.Table, held: dict[int, str]) -> list[ObjectOutcome]:
    """One outcome per sequence written or cleared: "in use" or "unused" as the file has it."""
    return [
        ObjectOutcome(f"sequence {number}", "in use" if number in table else "unused",
                      "failed" if difference else "verified", difference)
        for number, difference in held.items()
    ]  # fmt: skip


# ------------------------------------------------------------------------------------------------- helpers --
class _Reporter:
    """Progress events, about every 5 % (a WebSocket client does not need one per object)."""

    def __init__(self, progress: Progress | None, operation: str, node: int, file: str, total: int) -> None:
        self.progress, self.operation, self.node, self.file, self.total = progress, operation, node, file, total
        self.done = 0
        self.every = max(1, total // _PROGRESS_STEPS)
        self._lock = threading.Lock()
        self._emit()

    def step(self) -> None:
        with self._lock:  # done-callbacks run in the reader thread, or here when a future was already done
            if self.done >= self.total:  # a rewrite pass of the restore is not counted again
                return
            self.done += 1
            report = self.done % self.every == 0 or self.done == self.total
        if report:
            self._emit()

    def step_done(self, future: Future) -> None:
        """Done-callback of a transfer (runs in the bus reader thread, which completes the transfers in order)."""
        self.step()

    def finish(self) -> None:
        self.done = self.total
        self._emit()

    def _emit(self) -> None:
        if self.progress is not None:
            self.progress(
                {
                    "type": "progress",
                    "operation": self.operation,
                    "node": self.node,
                    "file": self.file,
                    "done": self.done,
                    "total": self.total,
                }
            )
