"""What the oscilloscope recorder records: the configuration of 0x5804–0x5822 checked and frozen at arm.

The recorder (`servostudio.sim.drive.recorder`) reads its configuration objects once, when it is armed, into a
`RecordingPlan`: a getter per enabled channel, the record's byte layout, the trigger and the re-arm mode. Writes to
the configuration are refused while it is armed, so the plan stays what the objects say. Layout and rules:
docs/eds.md §6, docs/scope.md.
"""

from __future__ import annotations

import struct
import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from itertools import starmap
from operator import itemgetter

from servostudio.od.datatypes import DataType
from servostudio.od.model import Value, Variable
from servostudio.sim import sdo_abort
from servostudio.sim.clock import CONTROL_PERIOD
from servostudio.sim.objects import ObjectStore
from servostudio.sim.sdo_abort import SdoAbort

BUFFER, CAPACITY, DEPTH, MULTIPLIER = 0x5804, 1, 2, 4
PRE_TRIGGER = 0x5805
CHANNEL_SOURCE = 0x5811
CHANNELS = (1, 2, 3, 4)
TRIGGER_CONFIG, TRIGGER_SOURCE, TRIGGER_MODE, REARM, AUTO_TIMEOUT = 0x5820, 1, 2, 3, 4
TRIGGER, LEVEL, EDGE = 0x5822, 1, 2
IMMEDIATE, EDGE_MODE = 0, 1
SINGLE, NORMAL, AUTO = 0, 1, 2
PERIODS_PER_MS = round(1e-3 / CONTROL_PERIOD)

FORMATS = {
    DataType.INTEGER8: "b",
    DataType.INTEGER16: "h",
    DataType.INTEGER32: "i",
    DataType.UNSIGNED8: "B",
    DataType.UNSIGNED16: "H",
    DataType.UNSIGNED32: "I",
    DataType.REAL32: "f",
}
"""The types a channel can hold (8, 16 and 32 bits), as little-endian `struct` codes equal to `od.encode`."""

Record = tuple[Value, ...]


def resolve_source(store: ObjectStore, pointer: int) -> Variable:
    """The object a source pointer `index << 16 | sub << 8 | size in bits` names, if the recorder can sample it;
    otherwise the abort the writer gets, the same rules as a TPDO mapping entry (so a source works in both)."""
    var = store.variable(pointer >> 16, (pointer >> 8) & 0xFF)
    if not (var.pdo_mappable and var.access.readable and var.data_type in FORMATS):
        raise SdoAbort(sdo_abort.CANNOT_BE_MAPPED, f"{var.label} cannot be recorded (not a PDO-mappable number)")
    if var.data_type.bits != pointer & 0xFF:
        raise SdoAbort(sdo_abort.CANNOT_BE_MAPPED, f"{var.label} has {var.data_type.bits} bits, not {pointer & 0xFF}")
    return var


def record_struct(types: Sequence[DataType]) -> struct.Struct:
    """One record: the channels' values in channel order, each little-endian in its CiA 301 encoding."""
    return struct.Struct("<" + "".join(FORMATS[data_type] for data_type in types))


def pack_records(layout: struct.Struct, records: Sequence[Record]) -> bytes:
    """The buffer object's bytes: the records one after the other."""
    return b"".join(starmap(layout.pack, records))


def _rising(previous: Value, current: Value, level: int) -> bool:
    return previous < level <= current  # type: ignore[operator]


def _falling(previous: Value, current: Value, level: int) -> bool:
    return previous > level >= current  # type: ignore[operator]


def _either(previous: Value, current: Value, level: int) -> bool:
    return _rising(previous, current, level) or _falling(previous, current, level)


EDGES = (_rising, _falling, _either)
"""0x5822,2: 0 rising, 1 falling, 2 either; each compares two successive records' trigger values with the level."""


@dataclass(frozen=True)
class Trigger:
    value_of: Callable[[Record], Value]
    """The trigger source's value at the instant of a record (a channel of it, or another object read then)."""
    level: int
    crossed: Callable[[Value, Value, int], bool]

    def fires(self, previous: Value, current: Value) -> bool:
        return self.crossed(previous, current, self.level)


@dataclass(frozen=True)
class RecordingPlan:
    readers: tuple[Callable[[], Value], ...]
    layout: struct.Struct
    depth: int
    multiplier: int
    pre_trigger: int
    trigger: Trigger | None
    """None in immediate mode: the recording starts at the arm."""
    rearm: int
    auto_records: int
    """Records taken while waiting after which auto mode forces the trigger (never in the other modes)."""


def plan_recording(store: ObjectStore) -> RecordingPlan:
    """The configuration objects as a plan, or abort 0x08000020 naming what makes the recording impossible."""
    sources = [int(store.get(CHANNEL_SOURCE, channel)) for channel in CHANNELS]
    variables = [resolve_source(store, pointer) for pointer in sources if pointer]
    if not variables:
        raise _impossible("no channel is on (0x5811)")
    layout = record_struct([var.data_type for var in variables])
    depth, multiplier = int(store.get(BUFFER, DEPTH)), int(store.get(BUFFER, MULTIPLIER))
    _check_capacity(depth * layout.size, int(store.get(BUFFER, CAPACITY)))
    edge_mode = int(store.get(TRIGGER_CONFIG, TRIGGER_MODE)) == EDGE_MODE
    pre_trigger = _pre_trigger(store, depth) if edge_mode else 0
    rearm = int(store.get(TRIGGER_CONFIG, REARM))
    return RecordingPlan(
        readers=tuple(store.value_reader(var) for var in variables),
        layout=layout,
        depth=depth,
        multiplier=multiplier,
        pre_trigger=pre_trigger,
        trigger=_trigger(store, sources) if edge_mode else None,
        rearm=rearm,
        auto_records=_auto_records(store, multiplier) if rearm == AUTO else sys.maxsize,
    )


def _impossible(reason: str) -> SdoAbort:
    return SdoAbort(sdo_abort.CANNOT_TRANSFER, f"cannot arm the recorder: {reason}")


def _check_capacity(needed: int, capacity: int) -> None:
    if needed > capacity:
        raise _impossible(f"depth x record size = {needed} bytes exceeds the buffer capacity of {capacity} bytes")


def _pre_trigger(store: ObjectStore, depth: int) -> int:
    pre_trigger = int(store.get(PRE_TRIGGER, 0))
    if pre_trigger > depth - 1:
        raise _impossible(f"pre-trigger {pre_trigger} leaves no room for the trigger record in depth {depth}")
    return pre_trigger


def _trigger(store: ObjectStore, sources: list[int]) -> Trigger:
    source = int(store.get(TRIGGER_CONFIG, TRIGGER_SOURCE))
    level, edge = int(store.get(TRIGGER, LEVEL)), int(store.get(TRIGGER, EDGE))
    return Trigger(_trigger_value(store, source, sources), level, EDGES[edge])


def _trigger_value(store: ObjectStore, source: int, sources: list[int]) -> Callable[[Record], Value]:
    """Channel n (1..4) is read from the record itself; any other source when the record is taken."""
    if source in CHANNELS:
        if not sources[source - 1]:
            raise _impossible(f"the trigger source is channel {source}, which is off")
        return itemgetter(sum(1 for pointer in sources[: source - 1] if pointer))
    read = store.value_reader(resolve_source(store, source))
    return lambda record: read()


def _auto_records(store: ObjectStore, multiplier: int) -> int:
    """0x5820,4 (ms) as the number of records taken while waiting, rounded up: the last of them is forced."""
    periods = int(store.get(TRIGGER_CONFIG, AUTO_TIMEOUT)) * PERIODS_PER_MS
    return -(-periods // multiplier)
