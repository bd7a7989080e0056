"""The drive's sequence memory (0x3610 selects a sequence, 0x3611,1..26 hold it) and its flash copy SEQUENCE.TXT.

A download is checked whole before the first frame: the text by the file reader (the one validation, with the
drive's 0x3612 and 0x360F), every write by the dictionary.  Then LOAD writes every slot below 0x3612 (the slots the
file does not declare are cleared), MERGE only the declared ones; the memory is read back and compared sequence by
sequence, and only a verified memory is stored to flash (``sseq``).  A link cut part-way leaves the flash copy as it
was, and the error says which sequences had reached RAM.
"""

from __future__ import annotations

import time
from collections.abc import Sequence as Listing
from concurrent.futures import Future
from dataclasses import dataclass, field

from servostudio.drive.access import Drive, DriveAccessError
from servostudio.drive.sdo import SdoError, settle
from servostudio.errors import CommunicationError, InvalidInput, NotFound
from servostudio.formats.sequence import (
    LoadMode,
    ObjectWrite,
    SequenceTable,
    SequenceType,
    parse_sequence_text,
)
from servostudio.od.model import Variable
from servostudio.services.sequences.graph import supported

FILE = "SEQUENCE.TXT"
#: procedure status (decisions.md §4): 2 running, 4 stopped on error, 5 done
RUNNING, FAILED, DONE = 2, 4, 5
PROCEDURE_TIMEOUT = 10.0
POLL = 0.02
SEQUENCE_SUBS = range(1, 27)


class NoSequences(NotFound):
    """The drive has no sequence memory (only the XtrapulsPac has sequence mode)."""


class SequenceTransferError(CommunicationError):
    """A download or upload that stopped part-way; the message says what reached the drive's RAM."""


class ProcedureFailed(InvalidInput):
    """The drive refused a sequence procedure (``sseq``, ``lseq``, ``mseq``): status 4, error 44."""


@dataclass(frozen=True)
class DriveLimits:
    """What the drive's sequence memory holds: numbers 0..count−1 (0x3612), the types 0x360F lists."""

    count: int
    types_mask: int

    @property
    def types(self) -> tuple[SequenceType, ...]:
        return tuple(kind for kind in SequenceType if supported(kind, self.types_mask))


@dataclass
class DownloadResult:
    node: int
    mode: str
    sequences: list[int]
    verified: bool
    stored: bool = False
    seconds: float = 0.0
    mismatched: list[int] = field(default_factory=list)

    def as_dict(self) -> dict[str, object]:
        return {
            "node": self.node,
            "mode": self.mode,
            "sequences": self.sequences,
            "verified": self.verified,
            "mismatched": self.mismatched,
            "stored": self.stored,
            "seconds": round(self.seconds, 3),
        }


def limits(drive: Drive) -> DriveLimits:
    """0x3612 and 0x360F; a drive without sequence memory is refused."""
    if not drive.profile.has_sequences:
        raise NoSequences(f"node {drive.node}: a {drive.profile.device} has no sequence mode")
    return DriveLimits(int(drive.read("max_sequences").raw), int(drive.read("sequence_supported_types").raw))


def validate(drive: Drive, text: str, file: str = FILE) -> tuple[SequenceTable, DriveLimits]:
    """The file read against this drive's limits (``SequenceFileError``: file, line, keyword, allowed range)."""
    found = limits(drive)
    return parse_sequence_text(text, file, max_sequences=found.count, types=found.types), found


def upload(drive: Drive) -> SequenceTable:
    """The sequence memory as a table (each slot's type first, then the 26 subs of the used ones)."""
    count = limits(drive).count
    number = drive.variable("sequence_number")
    kind = drive.variable("sequence_type")
    try:
        types = {n: _select_then(drive, number, n, [kind])[0] for n in range(count)}
        used = [n for n, future in types.items() if settle(future).raw != 0]
        subs = [drive.variable((kind.index, sub)) for sub in SEQUENCE_SUBS]
        pending = {n: _select_then(drive, number, n, subs) for n in used}
        records = {n: _record(futures) for n, futures in pending.items()}
    except SdoError as error:
        raise SequenceTransferError(f"node {drive.node}: reading the sequence memory stopped: {error}") from None
    try:
        return SequenceTable.from_object_values(records)
    except ValueError as error:
        raise InvalidInput(f"node {drive.node}: the memory holds what SEQUENCE.TXT cannot say: {error}") from None


def _record(futures: list[Future]) -> dict[int, int]:
    return {sub: int(settle(future).raw) for sub, future in zip(SEQUENCE_SUBS, futures, strict=True)}


def _select_then(drive: Drive, number: Variable, value: int, reads: Listing[Variable]) -> list[Future]:
    """0x3610 = value, then the reads, in the node's FIFO (bulk lane), so each read sees that sequence."""
    drive.submit_write(number, value, bulk=True)
    return [drive.submit_read(variable, bulk=True) for variable in reads]


def download(
    drive: Drive, text: str, mode: LoadMode = LoadMode.LOAD, store: bool = False, file: str = FILE
) -> DownloadResult:
    """Validate the whole file (``file`` is what messages call it), then write it to RAM (LOAD or MERGE), read it
    back, and store it if asked."""
    started = time.monotonic()
    table, found = validate(drive, text, file)
    writes = _planned(drive, table.to_object_writes(clear_below=found.count if mode is LoadMode.LOAD else None))
    _send(drive, table, writes)
    memory = upload(drive)
    expected = table.apply_to(memory, mode) if mode is LoadMode.MERGE else table
    numbers = sorted(set(expected) | set(memory))
    mismatched = [n for n in numbers if expected.sequences.get(n) != memory.sequences.get(n)]
    result = DownloadResult(drive.node, mode.value, list(table), not mismatched, mismatched=mismatched)
    if store and result.verified:
        store_to_flash(drive)
        result.stored = True
    result.seconds = time.monotonic() - started
    return result


def _planned(drive: Drive, writes: list[ObjectWrite]) -> list[tuple[ObjectWrite, Variable]]:
    """Every write checked by the dictionary before anything is sent."""
    try:
        return [(write, drive.prepare_write((write.index, write.sub), write.value)[0]) for write in writes]
    except DriveAccessError as error:
        raise InvalidInput(f"{FILE}: {error} — nothing was written to node {drive.node}") from None


def _send(drive: Drive, table: SequenceTable, writes: list[tuple[ObjectWrite, Variable]]) -> None:
    """All writes queued in order; on a failure, say which sequences had been written whole."""
    select = drive.profile.address("sequence_number")
    futures = [(write, drive.submit_write(variable, write.value, bulk=True)) for write, variable in writes]
    current, complete, failed = -1, [], None
    for write, future in futures:
        if (write.index, write.sub) == select and failed is None:
            if current >= 0:
                complete.append(current)
            current = write.value
        try:
            settle(future)
        except SdoError as error:
            failed = failed or error
    if failed is not None:
        reached = [n for n in complete if n in table] or "none"
        slots = sum((write.index, write.sub) == select for write, _ in writes)
        raise SequenceTransferError(
            f"node {drive.node}: the download stopped: {failed}. Sequences written to RAM: {reached} ({len(complete)} "
            f"of {slots} slots written whole, the others hold what they held); the flash copy (SEQUENCE.TXT) is "
            "unchanged — run the download again once the link is back"
        )


def store_to_flash(drive: Drive) -> None:
    """``sseq``: the sequence memory into the drive's SEQUENCE.TXT."""
    run_procedure(drive, "save_sequences")


def reload(drive: Drive, mode: LoadMode) -> None:
    """``lseq`` (LOAD) or ``mseq`` (MERGE): the drive's SEQUENCE.TXT into its sequence memory."""
    run_procedure(drive, "load_sequences" if mode is LoadMode.LOAD else "merge_sequences")


def run_procedure(drive: Drive, procedure: str) -> None:
    """Start a signature procedure and wait until its status leaves "running" (decisions.md §4)."""
    drive.start_procedure(procedure)
    status_object = drive.profile.signatures[procedure][0]
    deadline = time.monotonic() + PROCEDURE_TIMEOUT
    while (status := int(drive.read(status_object).raw)) == RUNNING and time.monotonic() < deadline:
        time.sleep(POLL)
    if status != DONE:
        raise ProcedureFailed(
            f"node {drive.node}: {procedure} ended with status {status} (4: the drive refused the sequence file, "
            "error 44)"
            if status == FAILED
            else f"node {drive.node}: {procedure} did not finish (status {status})"
        )
