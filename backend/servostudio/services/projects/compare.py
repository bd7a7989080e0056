"""Compare parameter values from several sources, object by object.

A source is anything with ``read(index, sub)``: the dictionary defaults, the project, a live drive
(``live.source.DriveValues``). Columns appear in the order the caller gives (the UI uses drive / project / default).

Which columns decide whether a row "differs" depends on the question: offline, a row differs when its columns are
not all equal; against a drive, it differs when the drive's value is not the project's (the default column is there
to read, not to compare). An object the project gives no value (no default, not set) cannot differ from the drive.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Protocol

from servostudio.od import ObjectDictionary, Variable
from servostudio.services.projects.axisvalues import AxisValues
from servostudio.services.projects.parameter_values import Value, normalize


class ParameterSource(Protocol):
    """Where a value of an object can be read: a project axis, the dictionary defaults, a drive."""

    def read(self, index: int, sub: int) -> Value | None: ...


class DefaultValues:
    """The dictionary defaults for one node (``$NODEID`` resolved)."""

    def __init__(self, dictionary: ObjectDictionary, node_id: int) -> None:
        self.dictionary = dictionary
        self.node_id = node_id

    def read(self, index: int, sub: int) -> Value | None:
        return self.dictionary[index, sub].default_for(self.node_id)


class ProjectValues:
    """The project value of each object: set in the axis files, else the default."""

    def __init__(self, axis_values: AxisValues) -> None:
        self.axis_values = axis_values

    def read(self, index: int, sub: int) -> Value | None:
        return self.axis_values.value(self.axis_values.dictionary[index, sub])


@dataclass(frozen=True)
class CompareRow:
    variable: Variable
    values: dict[str, Value | None]  # column name -> value (normalized)
    differs: bool


def compare(
    sources: Mapping[str, ParameterSource],
    variables: Iterable[Variable],
    *,
    group: str | None = None,
    only_differences: bool = False,
    between: tuple[str, str] | None = None,
) -> list[CompareRow]:
    """One row per variable (in the given order), optionally only one UI group and only rows that differ.

    ``between=(actual, reference)`` compares only those two columns, and a row whose reference column has no value
    never differs; without it every column takes part.
    """
    rows = []
    for variable in variables:
        if group is not None and variable.group.casefold() != group.casefold():
            continue
        values = {
            name: normalize(variable, source.read(variable.index, variable.subindex))
            for name, source in sources.items()
        }
        differs = _differs(values, between)
        if differs or not only_differences:
            rows.append(CompareRow(variable, values, differs))
    return rows


def _differs(values: Mapping[str, Value | None], between: tuple[str, str] | None) -> bool:
    if between is None:
        return len({_comparable(value) for value in values.values()}) > 1
    actual, reference = values[between[0]], values[between[1]]
    return reference is not None and _comparable(actual) != _comparable(reference)


def _comparable(value: Value | None) -> object:
    """Hashable form in which 1 == 1.0 but text never equals a number."""
    return (type(value) is str, value)
