"""The values a simulated drive holds, with the access rules and hooks of a bus access.

Two ways in: `get`/`set` are the drive model's own access (no checks, no hooks: the firmware writing its
measurements); `read_from_bus`/`write_from_bus` (and their byte forms) are what the SDO server, the PDOs and the
flash loader use: they check existence, access and range against the dictionary and run the hooks, through which
the drive behaviour gives objects side effects (`on_write`) or computed values (`on_read`).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from functools import partial
from typing import cast

from servostudio.od.datatypes import DataType, EncodingError, decode, encode
from servostudio.od.model import ObjectDictionary, Value, Variable
from servostudio.sim import sdo_abort
from servostudio.sim.sdo_abort import SdoAbort

WriteHook = Callable[[int, int, Value], object]  # what a hook returns is ignored
ReadHook = Callable[[int, int], Value]

_FIRST_SDO_ACCESSIBLE = 0x1000  # 0x0001–0x0FFF are data type definitions / dummy mapping entries


def zero_value(data_type: DataType) -> Value:
    """Zero of a type: the empty text, no bytes, 0.0 or 0."""
    if data_type.is_text:
        return ""
    if data_type.is_binary:
        return b""
    if data_type.is_float:
        return 0.0
    return 0


def undefined_default(var: Variable) -> Value:
    """What a new drive holds in an object whose dictionary entry has no DefaultValue: zero, or the limit nearest
    to it when zero is outside LowLimit..HighLimit (a drive never holds a value it would refuse on the bus, so a
    backup of a fresh drive restores)."""
    value = zero_value(var.data_type)
    if not var.data_type.is_numeric or not isinstance(value, (int, float)):
        return value
    if var.minimum is not None and value < var.minimum:
        return var.minimum
    if var.maximum is not None and value > var.maximum:
        return var.maximum
    return value


class ObjectStore:
    """Current value of every (index, sub) of one node, initialised from the dictionary defaults."""

    def __init__(self, od: ObjectDictionary, node_id: int) -> None:
        self.od = od
        self.node_id = node_id
        self._values: dict[tuple[int, int], Value] = {}
        self._write_hooks: dict[tuple[int, int | None], list[WriteHook]] = {}
        self._read_hooks: dict[tuple[int, int | None], list[ReadHook]] = {}
        self._hardware: dict[tuple[int, int], Value] = {}
        self.restore_defaults()

    def restore_defaults(self, indices: Iterable[int] | None = None) -> None:
        """Put the factory values back (all objects, or those whose index is in `indices`)."""
        wanted = None if indices is None else set(indices)
        for var in self.od.variables():
            if wanted is None or var.index in wanted:
                self._values[var.key] = self.factory_value(var)

    def factory_value(self, var: Variable) -> Value:
        """A new drive's value: the hardware's own (`set_factory`), else the dictionary default, else
        `undefined_default`."""
        if var.key in self._hardware:
            return self._hardware[var.key]
        default = var.default_for(self.node_id)
        return undefined_default(var) if default is None else default

    def set_factory(self, index: int, sub: int, value: Value) -> None:
        """A factory value the dictionary cannot know (ratings, node ID switches): stored now and after every
        `restore_defaults`."""
        self.set(index, sub, value)
        self._hardware[(index, sub)] = value

    # -- internal access (drive model) ---------------------------------------------------------------------------

    def get(self, index: int, sub: int = 0) -> Value:
        return self._values[(index, sub)]

    def values_by_name(self, addresses: dict[str, tuple[int, int]]) -> dict[str, Value]:
        """Many stored values at once, keyed by the caller's names (the drive model's parameter snapshot)."""
        values = self._values
        return {name: values[address] for name, address in addresses.items()}

    def reader(self, index: int, sub: int = 0) -> Callable[[], Value]:
        """A getter of one object's stored value: `get` without a Python call, for the per-period path."""
        if (index, sub) not in self._values:
            raise KeyError(f"0x{index:04X},{sub} is not in the {self.od.device} dictionary")
        return partial(self._values.__getitem__, (index, sub))

    def integer_reader(self, index: int, sub: int = 0) -> Callable[[], int]:
        """`reader` of an object of an integer type (the control word, the SYNC COB-ID), which holds an int."""
        var = self.od.get(index, sub)
        if var is not None and not var.data_type.is_integer:
            raise TypeError(f"{var.label} is a {var.data_type.name}, not an integer")
        return cast(Callable[[], int], self.reader(index, sub))

    def set(self, index: int, sub: int, value: Value) -> None:
        key = (index, sub)
        if key not in self._values:
            raise KeyError(f"0x{index:04X},{sub} is not in the {self.od.device} dictionary")
        self._values[key] = value

    def __contains__(self, key: tuple[int, int]) -> bool:
        return key in self._values

    # -- hooks ---------------------------------------------------------------------------------------------------

    def on_write(self, index: int, sub: int | None, callback: WriteHook) -> None:
        """`callback(index, sub, value)` runs before a bus write is stored (sub None: every sub of `index`)."""
        self._write_hooks.setdefault((index, sub), []).append(callback)

    def on_read(self, index: int, sub: int | None, callback: ReadHook) -> None:
        """`callback(index, sub)` computes the value a bus read returns (sub None: every sub of `index`)."""
        self._read_hooks.setdefault((index, sub), []).append(callback)

    # -- bus access ----------------------------------------------------------------------------------------------

    def variable(self, index: int, sub: int) -> Variable:
        """The dictionary entry, or the abort a client gets for a missing object / sub-index."""
        var = self.od.get(index, sub)
        if var is not None:
            return var
        if index in self.od:
            raise SdoAbort(sdo_abort.SUBINDEX_DOES_NOT_EXIST, f"0x{index:04X} has no sub-index {sub}")
        raise SdoAbort(sdo_abort.OBJECT_DOES_NOT_EXIST, f"0x{index:04X} is not in the dictionary")

    def read_from_bus(self, index: int, sub: int) -> Value:
        var = self._accessible(index, sub)
        if not var.access.readable:
            raise SdoAbort(sdo_abort.WRITE_ONLY, f"{var.label} is write-only")
        return self.read_value(var)

    def read_value(self, var: Variable) -> Value:
        """Current value including computed ones (the access right is the caller's business, e.g. a TPDO)."""
        hooks = self._read_hooks.get(var.key) or self._read_hooks.get((var.index, None))
        if hooks:
            return hooks[-1](var.index, var.subindex)
        return self._values[var.key]

    def value_reader(self, var: Variable) -> Callable[[], Value]:
        """A getter of what `read_value(var)` returns at the time of each call, its hook looked up once: for code
        that samples an object every control period (the oscilloscope recorder)."""
        hooks = self._read_hooks.get(var.key) or self._read_hooks.get((var.index, None))
        if hooks:
            return partial(hooks[-1], var.index, var.subindex)
        return partial(self._values.__getitem__, var.key)

    def write_from_bus(self, index: int, sub: int, value: Value) -> None:
        var = self._accessible(index, sub)
        if not var.access.writable:
            raise SdoAbort(sdo_abort.READ_ONLY, f"{var.label} is read-only")
        self.write_value(var, value)

    def write_value(self, var: Variable, value: Value) -> None:
        """Range check, hooks, store — without the access check (used for RPDOs after mapping checks and flash)."""
        check_range(var, value)
        for hook in self._write_hooks.get(var.key, ()):
            hook(var.index, var.subindex, value)
        for hook in self._write_hooks.get((var.index, None), ()):
            hook(var.index, var.subindex, value)
        self._values[var.key] = value

    def read_bytes(self, index: int, sub: int) -> bytes:
        """Bus read encoded as the object's CANopen bytes (what an SDO upload sends)."""
        var = self._accessible(index, sub)
        value = self.read_from_bus(index, sub)
        try:
            return encode(var.data_type, value)
        except EncodingError as exc:
            raise SdoAbort(sdo_abort.GENERAL, f"{var.label} holds {value!r}: {exc}") from exc

    def write_bytes(self, index: int, sub: int, raw: bytes) -> None:
        """Bus write of CANopen bytes (what an SDO download delivers)."""
        var = self._accessible(index, sub)
        if not var.access.writable:
            raise SdoAbort(sdo_abort.READ_ONLY, f"{var.label} is read-only")
        size = var.data_type.size
        if size is not None and len(raw) != size:
            code = sdo_abort.LENGTH_TOO_HIGH if len(raw) > size else sdo_abort.LENGTH_TOO_LOW
            raise SdoAbort(code, f"{var.label} takes {size} byte(s), got {len(raw)}")
        try:
            value = decode(var.data_type, raw)
        except EncodingError as exc:
            raise SdoAbort(sdo_abort.LENGTH_MISMATCH, f"{var.label}: {exc}") from exc
        self.write_value(var, value)

    def _accessible(self, index: int, sub: int) -> Variable:
        var = self.variable(index, sub)
        if index < _FIRST_SDO_ACCESSIBLE:
            raise SdoAbort(sdo_abort.UNSUPPORTED_ACCESS, f"{var.label} is a mapping-only object")
        return var


def check_range(var: Variable, value: Value) -> None:
    """Abort 0x06090031/0x06090032 when a number lies outside the object's limits."""
    if not (var.data_type.is_numeric and isinstance(value, (int, float))):
        return
    low, high = var.minimum, var.maximum
    if high is not None and value > high:
        raise SdoAbort(sdo_abort.VALUE_TOO_HIGH, f"{var.label}: {value} > {high}")
    if low is not None and value < low:
        raise SdoAbort(sdo_abort.VALUE_TOO_LOW, f"{var.label}: {value} < {low}")
