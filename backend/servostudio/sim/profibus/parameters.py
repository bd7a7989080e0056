"""The parameter memory of a simulated TTA-PRO: one value per (PNU, IND) from the parameter list, the checks a
PKW instruction goes through, and the EEPROM copy of the E parameters that PNU 729 writes.

Checks and their PKW error numbers (TTA-PRO Profibus Communication Profile, Chapter 1 §3.2, L334-344): unknown
PNU 0, write to a read-only PNU 1, outside Min..Max 2, IND outside the PNU's range (or IND on a plain PNU) 3,
AK 2 on a double word or AK 3 on a word 5, a hook refusing in the present state 17, reading a write-only PNU 18.
"""

from __future__ import annotations

from collections.abc import Callable

from servostudio.od.datatypes import DataType
from servostudio.od.pnu_model import Parameter, ParameterDictionary, Persistence

ILLEGAL_PNU = 0
NOT_MODIFIABLE = 1
LIMIT_EXCEEDED = 2
INDEX_ERROR = 3
WRONG_TYPE = 5
NOT_IN_THIS_STATE = 17
OTHER_ERROR = 18

WriteHook = Callable[[int, int], None]
"""(index, value) before the value is stored; raises PkwRefusal to refuse it."""
ReadHook = Callable[[int], int]
"""index -> the value a read returns (computed monitors)."""


class PkwRefusal(Exception):
    """An instruction the drive does not carry out: AK 7 with `error` in PWE."""

    def __init__(self, error: int, detail: str) -> None:
        self.error = error
        super().__init__(f"PKW error {error}: {detail}")


def initial_value(parameter: Parameter, index: int) -> int:
    """The default, else the value nearest to 0 within the limits (a fresh drive passes its own checks)."""
    default = parameter.default_at(index)
    if default is not None:
        return default
    low = parameter.low if parameter.low is not None else int(parameter.data_type.min_value or 0)
    high = parameter.high if parameter.high is not None else int(parameter.data_type.max_value or 0)
    return min(max(0, low), high)


class ParameterMemory:
    """RAM values plus the EEPROM image; `get`/`set` are the drive model's unchecked access, `read`/`write` the
    PKW instruction's checked one."""

    def __init__(self, parameters: ParameterDictionary) -> None:
        self.parameters: dict[int, Parameter] = dict(parameters.parameters)
        self.values = {
            (pnu, index): initial_value(parameter, index)
            for pnu, parameter in self.parameters.items()
            for index in parameter.index_range
        }
        self.eeprom = {key: value for key, value in self.values.items() if self._saved(key[0])}
        self._write_hooks: dict[int, list[WriteHook]] = {}
        self._read_hooks: dict[int, ReadHook] = {}

    def _saved(self, pnu: int) -> bool:
        return self.parameters[pnu].persistence is Persistence.E

    # -- drive model ------------------------------------------------------------------------------------------

    def get(self, pnu: int, index: int = 0) -> int:
        return self.values[(pnu, index)]

    def set(self, pnu: int, value: int, index: int = 0) -> None:
        self.values[(pnu, index)] = value

    def on_write(self, pnu: int, hook: WriteHook) -> None:
        """Hooks run in the order they were added; the first that refuses stops the write."""
        self._write_hooks.setdefault(pnu, []).append(hook)

    def on_read(self, pnu: int, hook: ReadHook) -> None:
        self._read_hooks[pnu] = hook

    def save_eeprom(self) -> None:
        """PNU 729: every E parameter into the EEPROM."""
        self.eeprom = {key: value for key, value in self.values.items() if self._saved(key[0])}

    def load_eeprom(self) -> None:
        """Power-up: the E parameters come back from the EEPROM, everything else from its default."""
        self.values.update(self.eeprom)

    # -- PKW instruction --------------------------------------------------------------------------------------

    def parameter(self, pnu: int, index: int) -> Parameter:
        parameter = self.parameters.get(pnu)
        if parameter is None:
            raise PkwRefusal(ILLEGAL_PNU, f"PNU {pnu} does not exist")
        if index not in parameter.index_range:
            raise PkwRefusal(INDEX_ERROR, f"PNU {pnu} has no IND {index}")
        return parameter

    def read(self, pnu: int, index: int) -> int:
        parameter = self.parameter(pnu, index)
        if not parameter.access.readable:
            raise PkwRefusal(OTHER_ERROR, f"PNU {pnu} is write-only")
        hook = self._read_hooks.get(pnu)
        return hook(index) if hook is not None else self.values[(pnu, index)]

    def write(self, pnu: int, index: int, value: int, double: bool) -> None:
        """`value` is already the parameter's own signed or unsigned reading of PWE."""
        parameter = self.parameter(pnu, index)
        if not parameter.access.writable:
            raise PkwRefusal(NOT_MODIFIABLE, f"PNU {pnu} is read-only")
        if parameter.is_double != double:
            raise PkwRefusal(WRONG_TYPE, f"PNU {pnu} is a {'double word' if parameter.is_double else 'word'}")
        check_range(parameter, value)
        for hook in self._write_hooks.get(pnu, ()):
            hook(index, value)
        self.values[(pnu, index)] = value


def check_range(parameter: Parameter, value: int) -> None:
    low = parameter.low if parameter.low is not None else parameter.data_type.min_value
    high = parameter.high if parameter.high is not None else parameter.data_type.max_value
    if (low is not None and value < low) or (high is not None and value > high):
        raise PkwRefusal(LIMIT_EXCEEDED, f"PNU {parameter.pnu}: {value} is outside {low}..{high}")


def is_signed(parameter: Parameter) -> bool:
    return parameter.data_type in (DataType.INTEGER16, DataType.INTEGER32)
