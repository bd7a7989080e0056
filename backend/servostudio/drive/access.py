"""Drive access: read and write any object of one node through its object dictionary.

Every check that can be made without the drive — does the object exist, may it be read or written, does the
value fit its type, range and enumeration — is made before a frame is sent, and the error names the node and the
object.  The drive's own refusals arrive as SDO aborts translated by ``servostudio.drive.sdo``.

Methods block the calling thread (they wait on the SDO engine); the ``submit_*`` variants return futures so
many reads can be queued at once and awaited from asyncio with ``asyncio.wrap_future``; ``submit_read_all`` and
``submit_write_all`` transfer a whole list (a backup, a restore) with one future.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from concurrent.futures import CancelledError, Future
from dataclasses import dataclass
from typing import Protocol

from servostudio.drive.object_values import ObjectValue, Raw, decode_raw, parse_input
from servostudio.drive.profiles import DeviceProfile, profile_for
from servostudio.drive.sdo import SAFETY_WAIT, SdoEngine, TransferBatch, settle
from servostudio.errors import InvalidInput, NotFound
from servostudio.od.datatypes import DataType, encode
from servostudio.od.model import Access, ObjectDictionary, Variable

#: Safety net only (`servostudio.drive.sdo.SAFETY_WAIT`): the engine completes every transfer itself.
DEFAULT_WAIT = SAFETY_WAIT


class DriveAccessError(InvalidInput):
    """A read or write refused before anything was sent (unknown object, access, value)."""


class UnknownObjectError(NotFound, DriveAccessError):
    """The object is not in the drive's dictionary (or no dictionary is known for the drive)."""


@dataclass(frozen=True)
class PlannedWrite:
    """One write as the drive will receive it: the raw value the dictionary made of the caller's input (type and
    range checked), so whoever judges it sees what the drive will see, not how the caller spelled it."""

    index: int
    sub: int
    raw: Raw
    variable: Variable | None = None  # None: bytes to an object the dictionary may not know (a procedure signature)

    @property
    def key(self) -> tuple[int, int]:
        return (self.index, self.sub)


#: What a gate hears once the writes it let through are done: per write, in order, the value written or the error.
WriteOutcomes = Callable[[Sequence[object]], None]


class WriteGate(Protocol):
    """Every write of a :class:`Drive` passes its gate after the dictionary converted it and before a frame is sent:
    the gate refuses by raising, and hears the outcomes.  The server's gate is the motion guard with the audit log
    (``services.motion``); the drive layer alone lets everything through."""

    def admit(self, drive: Drive, writes: Sequence[PlannedWrite]) -> WriteOutcomes: ...


class OpenGate:
    """Lets every write through and records nothing: drive access on its own, without the server's services."""

    def admit(self, drive: Drive, writes: Sequence[PlannedWrite]) -> WriteOutcomes:
        return _ignore_outcomes


def _ignore_outcomes(outcomes: Sequence[object]) -> None:
    """An open gate records nothing."""


OPEN_GATE = OpenGate()


class Drive:
    """One node on one bus, with its dictionary and device profile."""

    def __init__(
        self,
        engine: SdoEngine,
        node: int,
        dictionary: ObjectDictionary | None,
        profile: DeviceProfile | None = None,
        gate: WriteGate = OPEN_GATE,
    ) -> None:
        self.engine = engine
        self.node = node
        self.dictionary = dictionary
        self.profile = profile or profile_for(dictionary.device if dictionary else None)
        self.gate = gate

    def __repr__(self) -> str:
        return f"Drive(node={self.node}, device={self.profile.device!r})"

    # -- object lookup -------------------------------------------------------------------------------------------
    def variable(self, key: str | tuple[int, int]) -> Variable:
        """An object by address ("0x6041", "0x60F9,2"), (index, sub) or name; a profile name ("statusword") too."""
        if isinstance(key, str) and self.profile.has(key):
            key = self.profile.address(key)
        if self.dictionary is None:
            raise UnknownObjectError(
                f"node {self.node}: no object dictionary known (the node did not answer or "
                "matches no EDS of the library); scan the bus or name the device"
            )
        try:
            if isinstance(key, tuple):
                return self.dictionary[key]
            return self.dictionary.find(key)
        except KeyError:
            shown = f"0x{key[0]:04X},{key[1]}" if isinstance(key, tuple) else repr(key)
            raise UnknownObjectError(
                f"node {self.node}: object {shown} is not in the {self.dictionary.device} dictionary"
            ) from None

    # -- reads ---------------------------------------------------------------------------------------------------
    def submit_read(self, variable: Variable, timeout: float | None = None, bulk: bool = False) -> Future:
        """Queue a read; the future gives an ObjectValue (``bulk``: part of a long operation, served after the
        interactive requests of the node)."""
        if not variable.access.readable:
            raise DriveAccessError(f"node {self.node}: {variable.label} is write-only")
        return self.engine.upload(
            self.node,
            variable.index,
            variable.subindex,
            timeout,
            convert=lambda data: ObjectValue(self.node, variable, decode_raw(variable, data)),
            bulk=bulk,
        )

    def submit_read_all(
        self, variables: Sequence[Variable], on_each: Callable[[int, ObjectValue | Exception], None] | None = None
    ) -> TransferBatch[ObjectValue]:
        """Queue reads of many objects at once; the batch's future gives, in order, an ObjectValue or the exception
        that ended each read (see `TransferBatch`)."""
        for variable in variables:
            if not variable.access.readable:
                raise DriveAccessError(f"node {self.node}: {variable.label} is write-only")
        return self.engine.upload_all(
            self.node,
            [(variable.index, variable.subindex) for variable in variables],
            convert=lambda position, data: ObjectValue(
                self.node, variables[position], decode_raw(variables[position], data)
            ),
            on_each=on_each,
        )

    def read(self, key: str | tuple[int, int] | Variable, timeout: float | None = None) -> ObjectValue:
        variable = key if isinstance(key, Variable) else self.variable(key)
        return settle(self.submit_read(variable, timeout), DEFAULT_WAIT + (timeout or 0))

    # -- writes --------------------------------------------------------------------------------------------------
    def prepare_write(
        self,
        key: str | tuple[int, int] | Variable,
        value: object,
        physical: bool = False,
    ) -> tuple[Variable, Raw, bytes]:
        """Check a write completely without sending anything; returns (variable, raw value, bytes to send)."""
        variable = key if isinstance(key, Variable) else self.variable(key)
        if not variable.access.writable:
            kind = "constant" if variable.access is Access.CONST else "read-only"
            raise DriveAccessError(f"node {self.node}: {variable.label} is {kind}")
        try:
            raw = parse_input(variable, value, physical)
            data = encode(DataType(variable.data_type), raw)
        except ValueError as error:
            raise DriveAccessError(f"node {self.node}: {error}") from None
        return variable, raw, data

    def submit_write(
        self,
        key: str | tuple[int, int] | Variable,
        value: object,
        physical: bool = False,
        timeout: float | None = None,
        bulk: bool = False,
    ) -> Future:
        """Check, pass the gate, then queue a write; the future gives the ObjectValue written (``bulk`` as for
        `submit_read`)."""
        variable, raw, data = self.prepare_write(key, value, physical)
        heard = self.gate.admit(self, [PlannedWrite(variable.index, variable.subindex, raw, variable)])
        future = self.engine.download(
            self.node,
            variable.index,
            variable.subindex,
            data,
            timeout,
            convert=lambda _: ObjectValue(self.node, variable, raw),
            bulk=bulk,
        )
        future.add_done_callback(lambda done: heard([_outcome(done)]))
        return future

    def submit_write_all(
        self,
        writes: Sequence[tuple[Variable, object]],
        on_each: Callable[[int, ObjectValue | Exception], None] | None = None,
    ) -> TransferBatch[ObjectValue]:
        """Check every write and pass the gate with all of them, then queue them all (nothing is sent if one fails
        its check or the gate refuses); the batch's future gives, in order, the ObjectValue written or the exception
        that ended each write (see `TransferBatch`)."""
        prepared = [self.prepare_write(variable, value) for variable, value in writes]
        heard = self.gate.admit(self, [PlannedWrite(var.index, var.subindex, raw, var) for var, raw, _ in prepared])
        batch = self.engine.download_all(
            self.node,
            [(variable.index, variable.subindex, data) for variable, _, data in prepared],
            convert=lambda position, _: ObjectValue(self.node, prepared[position][0], prepared[position][1]),
            on_each=on_each,
        )
        batch.future.add_done_callback(lambda done: heard(_batch_outcomes(done, len(prepared))))
        return batch

    def write(
        self, key: str | tuple[int, int] | Variable, value: object, physical: bool = False, timeout: float | None = None
    ) -> ObjectValue:
        return settle(self.submit_write(key, value, physical, timeout), DEFAULT_WAIT + (timeout or 0))

    def write_raw_bytes(self, index: int, sub: int, data: bytes, timeout: float | None = None) -> None:
        """Write bytes to an object the dictionary may not know (procedure signatures on unknown devices); the gate
        sees them as the integer the drive reads (little-endian), as a typed write of the object would give."""
        raw: Raw = int.from_bytes(data, "little") if len(data) <= 4 else data
        heard = self.gate.admit(self, [PlannedWrite(index, sub, raw)])
        future = self.engine.download(self.node, index, sub, data, timeout)
        future.add_done_callback(lambda done: heard([_outcome(done)]))
        settle(future, DEFAULT_WAIT + (timeout or 0))

    def start_procedure(self, procedure: str, timeout: float = 10.0) -> None:
        """Write a procedure's signature (decisions.md §4), e.g. "save" → 0x1010,1 = 'save'."""
        (index, sub), value = self.profile.signature(procedure)
        self.write_raw_bytes(index, sub, value.to_bytes(4, "little"), timeout)


def _outcome(done: Future) -> object:
    """A finished transfer as the gate hears it: the value, or the exception that ended it."""
    error = done.exception() if not done.cancelled() else CancelledError()
    return error if error is not None else done.result()


def _batch_outcomes(done: Future, count: int) -> Sequence[object]:
    """A finished batch as the gate hears it: its outcomes, or the one error that ended them all."""
    outcome = _outcome(done)
    return outcome if isinstance(outcome, list) else [outcome] * count
