"""A sequence table behind a buffer (the TTA-PRO's 128 sequences) and its backup file TTASEQ.TXT
(docs/profibus.md §13).

The drive keeps the sequences in EEPROM, reached only through a buffer (``drive/profiles/sequence_buffer.py``):
reading sequence n is the ``read`` procedure with n, then one read per field; writing it is one write per field,
then the ``write`` procedure with n. Every transfer of a table goes on the node's bulk lane in order, so each field
read sees the sequence copied into the buffer just before it, and all of them are queued at once (the engine keeps
the drive busy back to back). A table is read in two passes: the control word of every sequence, then every field
of the sequences in use (control word ≠ 0) — most tables use few of the 128.

TTASEQ.TXT is TTAPAR.TXT's syntax (``PNU,IND=value``, ``formats/parameterfile.py``) with IND = the sequence number
and PNU = a buffer field: ``783,5=120000`` is the position of sequence 5. A sequence in the file gives every field;
the sequences it does not list are unused. The backup service (``services/backup.py``) decides what a backup and a
restore are; this module only speaks the buffer protocol and the file.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from concurrent.futures import Future

from servostudio.drive.access import Drive
from servostudio.drive.object_values import parse_input
from servostudio.drive.profiles import DeviceProfile
from servostudio.drive.profiles.sequence_buffer import SequenceBuffer
from servostudio.drive.sdo import settle
from servostudio.errors import Conflict
from servostudio.formats.objectfile import ObjectEntry, ObjectFileError
from servostudio.formats.parameterfile import by_ind, format_parameter_file, parse_parameter_file
from servostudio.od.model import ObjectDictionary, Variable

Fields = dict[str, int]
"""One sequence: field (semantic name) → raw value."""
Table = dict[int, Fields]
"""The sequences in use by number."""
Step = Callable[[], None]


class SequenceTableInvalid(ObjectFileError):
    """A TTASEQ.TXT that cannot be written: ``FILE:LINE: reason``."""


def buffer_of(drive: Drive) -> SequenceBuffer:
    return _buffer(drive.profile)


def _buffer(profile: DeviceProfile) -> SequenceBuffer:
    if profile.sequence_buffer is None:
        raise Conflict(f"a {profile.device} keeps no sequence table behind a buffer")
    return profile.sequence_buffer


# --------------------------------------------------------------------------------------------------- reading --
def read_table(drive: Drive, step: Step | None = None) -> Table:
    """The sequences in use; SdoError (the link, a refusal) as the transfers raise it."""
    buffer = buffer_of(drive)
    used = [number for number, control in read_controls(drive, step).items() if control]
    records = {number: _queue_sequence_read(drive, buffer, number, buffer.fields) for number in used}
    return {number: _values(record) for number, record in records.items()}


def read_controls(drive: Drive, step: Step | None = None) -> dict[int, int]:
    """The control word of every sequence (0: unused), ``step`` called once per sequence."""
    buffer = buffer_of(drive)
    queued = {number: _queue_sequence_read(drive, buffer, number, (buffer.control,)) for number in range(buffer.count)}
    controls = {}
    for number, record in queued.items():
        controls[number] = _values(record)[buffer.control]
        if step is not None:
            step()
    return controls


Queued = tuple[Future, dict[str, Future]]
"""The copy of a sequence into the buffer, and the reads of its fields."""


def _queue_sequence_read(drive: Drive, buffer: SequenceBuffer, number: int, fields: tuple[str, ...]) -> Queued:
    """Copy sequence ``number`` into the buffer, then read ``fields`` of it."""
    copied = drive.submit_write(buffer.read, number, bulk=True)
    return copied, {name: drive.submit_read(drive.variable(name), bulk=True) for name in fields}


def _values(queued: Queued) -> Fields:
    """The fields' values once the copy and every read are done (a failed copy raises before any value counts)."""
    copied, reads = queued
    settle(copied)
    return {name: int(settle(future).raw) for name, future in reads.items()}


# --------------------------------------------------------------------------------------------------- writing --
def write_table(drive: Drive, table: Table, step: Step | None = None) -> dict[int, str]:
    """Write ``table`` as the whole sequence table: its sequences, and 0 into the control word of every other
    sequence in use (the unused ones are left alone, so they stay unused); then read back what was written. Returns
    every sequence written or cleared → "" when the drive holds what the file says, else what it holds instead.
    The checksum is not written here (`store_checksum`)."""
    buffer = buffer_of(drive)
    held = read_controls(drive, step)
    cleared = {number: {buffer.control: 0} for number, control in held.items() if control and number not in table}
    wanted = dict(sorted({**table, **cleared}.items()))
    writes = [_queue_sequence_write(drive, buffer, number, fields) for number, fields in wanted.items()]
    for future in (future for futures in writes for future in futures):
        settle(future)
    reads = {number: _queue_sequence_read(drive, buffer, number, tuple(fields)) for number, fields in wanted.items()}
    return {number: _difference(wanted[number], _values(queued)) for number, queued in reads.items()}


def _queue_sequence_write(drive: Drive, buffer: SequenceBuffer, number: int, fields: Fields) -> list[Future]:
    """Fill the buffer with ``fields``, then copy it into sequence ``number``."""
    writes = [drive.submit_write(name, value, bulk=True) for name, value in fields.items()]
    return [*writes, drive.submit_write(buffer.write, number, bulk=True)]


def _difference(wanted: Fields, found: Fields) -> str:
    """What the drive holds instead of ``wanted``; "" when it holds it."""
    return ", ".join(f"{name} {found[name]}" for name in wanted if found[name] != wanted[name])


def store_checksum(drive: Drive) -> str:
    """The ``write`` procedure with the checksum value: the table is consistent at the next power-up. Returns what
    a result reports as stored."""
    buffer = buffer_of(drive)
    drive.write(buffer.write, buffer.checksum_value)
    return f"sequence checksum ({buffer.write} = {buffer.checksum_value})"


# ------------------------------------------------------------------------------------------------------ file --
def format_table(profile: DeviceProfile, table: Table, header: str | None = None) -> str:
    """TTASEQ.TXT's canonical text: ``PNU,IND=value`` by sequence, each sequence's fields by PNU."""
    pnus = {name: profile.address(name)[0] for name in _buffer(profile).fields}
    entries = [
        ObjectEntry(pnus[name], number, value) for number, fields in table.items() for name, value in fields.items()
    ]
    return format_parameter_file(entries, header, by_ind)


def parse_table(profile: DeviceProfile, dictionary: ObjectDictionary, text: str, name: str) -> Table:
    """The table a TTASEQ.TXT holds, checked whole against the device's parameter list (each field's type and
    range; no drive needed: a project's file is checked offline too); SequenceTableInvalid ``NAME:LINE: reason`` on
    the first problem. Sequences whose control word is 0 are unused, as if not listed."""
    buffer = _buffer(profile)
    fields = {profile.address(field)[0]: field for field in buffer.fields}
    variables = {pnu: dictionary[profile.address(field)] for pnu, field in fields.items()}
    table: Table = {}
    first_lines: dict[int, int] = {}

    def validate(entry: ObjectEntry) -> str | None:
        problem = _entry_problem(buffer, variables, entry)
        if problem is None:
            table.setdefault(entry.sub, {})[fields[entry.index]] = int(entry.value)
            first_lines.setdefault(entry.sub, entry.line)
        return problem

    try:
        parse_parameter_file(text, name, validate)
    except ObjectFileError as error:
        raise SequenceTableInvalid(error.file, error.line, error.reason) from None
    _check_complete(buffer, table, first_lines, name)
    return {number: record for number, record in sorted(table.items()) if record[buffer.control]}


def _entry_problem(buffer: SequenceBuffer, fields: Mapping[int, Variable], entry: ObjectEntry) -> str | None:
    if entry.index not in fields:
        return f"PNU {entry.index} is no sequence field (PNU {min(fields)}-{max(fields)})"
    if entry.sub >= buffer.count:
        return f"IND {entry.sub}: the sequences are numbered 0-{buffer.count - 1}"
    try:
        parse_input(fields[entry.index], entry.value)
    except ValueError as error:
        return f"sequence {entry.sub}: {error}"
    return None


def _check_complete(buffer: SequenceBuffer, table: Table, first_lines: dict[int, int], name: str) -> None:
    """Every listed sequence gives every field: the buffer keeps what the previous sequence left in it."""
    for number, record in table.items():
        missing = [field for field in buffer.fields if field not in record]
        if missing:
            reason = f"sequence {number} lacks {', '.join(missing)} (a listed sequence gives every field)"
            raise SequenceTableInvalid(name, first_lines[number], reason)
