"""Offline parameter editing: read, set and reset the values of an axis in its project, without a drive.

Every write is checked like an online write (the object exists, is writable, the value fits its type and limits)
plus the project rule that the object must be saved in a drive file; several values change together or not at all.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Protocol

from servostudio.od import LibraryError, ObjectDictionary, SaveType, Variable
from servostudio.services.projects.axisvalues import AxisValues
from servostudio.services.projects.compare import CompareRow, DefaultValues, ParameterSource, ProjectValues, compare
from servostudio.services.projects.errors import ParameterRefused, ProjectNotFound
from servostudio.services.projects.model import Axis
from servostudio.services.projects.parameter_values import Value
from servostudio.services.projects.revisions import keeping
from servostudio.services.projects.store import ProjectEdit, ProjectStore


class DictionaryLibrary(Protocol):
    def devices(self) -> list[str]: ...
    def load(self, device: str) -> ObjectDictionary: ...


@dataclass(frozen=True)
class ParameterRow:
    """One object as the project sees it: its value, its default, and whether and where the project sets it."""

    variable: Variable
    value: Value | None
    default: Value | None
    file: str | None  # the axis file that sets it; None = follows the default
    editable_reason: str | None  # None = editable offline

    @property
    def differs_from_default(self) -> bool:
        return self.value != self.default


@dataclass(frozen=True)
class ParameterChange:
    rows: list[ParameterRow]
    revision: str


class ParameterService:
    def __init__(self, store: ProjectStore, library: DictionaryLibrary) -> None:
        self.store = store
        self.library = library

    def dictionary(self, axis: Axis) -> ObjectDictionary:
        try:
            return self.library.load(axis.device)
        except LibraryError as error:
            raise ProjectNotFound(f"axis '{axis.name}': {error}") from None

    def rows(
        self,
        project: str,
        axis: str,
        *,
        group: str | None = None,
        only_set: bool = False,
        only_differences: bool = False,
        include_unsaved: bool = False,
    ) -> tuple[list[ParameterRow], str]:
        """The parameters of an axis (objects saved in a drive file, or every object with ``include_unsaved``)."""
        with self.store.read(project) as view:
            values = self._load(view, axis)
            rows = []
            for variable in values.dictionary.variables():
                if not include_unsaved and variable.save_type is SaveType.NONE:
                    continue
                if group is not None and variable.group.casefold() != group.casefold():
                    continue
                row = parameter_row(values, variable)
                if (only_set and row.file is None) or (only_differences and not row.differs_from_default):
                    continue
                rows.append(row)
            return rows, view.revision

    def get(self, project: str, axis: str, address: str) -> tuple[ParameterRow, str]:
        with self.store.read(project) as view:
            values = self._load(view, axis)
            return parameter_row(values, values.resolve(address)), view.revision

    def set(
        self,
        project: str,
        axis: str,
        changes: Mapping[str, object],
        expected_revision: str | None = None,
        keep: str | None = None,
    ) -> ParameterChange:
        """Set several objects (address -> value) at once; any refusal leaves every file unchanged. With ``keep``
        (why), the project as it was stays restorable (``revisions``): a change that replaces many values."""
        if not changes:
            raise ParameterRefused("no parameter given")
        with self.store.edit(project, expected_revision) as edit, _keeping(edit, keep):
            values = self._load(edit, axis)
            touched = [values.resolve(address) for address in changes]
            for variable, raw in zip(touched, changes.values(), strict=True):
                values.stage(variable, raw)
            values.commit(edit, axis)
        return ParameterChange([parameter_row(values, variable) for variable in touched], edit.revision)

    def unset(
        self, project: str, axis: str, addresses: Iterable[str], expected_revision: str | None = None
    ) -> ParameterChange:
        """Remove the project's values of these objects: they follow the dictionary default again."""
        with self.store.edit(project, expected_revision) as edit:
            values = self._load(edit, axis)
            touched = [values.resolve(address) for address in addresses]
            for variable in touched:
                values.unset(variable)
            values.commit(edit, axis)
        return ParameterChange([parameter_row(values, variable) for variable in touched], edit.revision)

    def compare(
        self,
        project: str,
        axis: str,
        *,
        group: str | None = None,
        only_differences: bool = False,
        drive: ParameterSource | None = None,
    ) -> tuple[list[CompareRow], str]:
        """Columns project / default for every saved, writable object of the axis; with a ``drive``, columns drive /
        project / default for the objects drive and project exchange (:meth:`AxisValues.transferable`), and a row
        differs when the drive's value is not the project's. Read-only entries are apart: :meth:`read_only`."""
        with self.store.read(project) as view:
            values = self._load(view, axis)
            sources: dict[str, ParameterSource] = {}
            if drive is not None:
                sources["drive"] = drive
            sources["project"] = ProjectValues(values)
            sources["default"] = DefaultValues(values.dictionary, values.node_id)
            if drive is None:
                chosen = [
                    v for v in values.dictionary.variables() if v.save_type is not SaveType.NONE and v.access.writable
                ]
            else:
                chosen = values.transferable()
            rows = compare(
                sources,
                chosen,
                group=group,
                only_differences=only_differences,
                between=("drive", "project") if drive is not None else None,
            )
            return rows, view.revision

    def read_only(
        self, project: str, axis: str, *, group: str | None = None, drive: ParameterSource | None = None
    ) -> list[CompareRow]:
        """The entries a compare does not count: read-only ones (error register, status word, measurements), which
        nobody writes or restores; shown apart, with the drive's value when there is a drive."""
        with self.store.read(project) as view:
            values = self._load(view, axis)
            sources: dict[str, ParameterSource] = {} if drive is None else {"drive": drive}
            sources["project"] = ProjectValues(values)
            sources["default"] = DefaultValues(values.dictionary, values.node_id)
            between = ("drive", "project") if drive is not None else None
            return compare(sources, read_only_variables(values.dictionary), group=group, between=between)

    def read_only_variables(self, project: str, axis: str, group: str | None = None) -> list[Variable]:
        """The read-only entries of an axis (optionally one UI group): what a drive source must read for them."""
        with self.store.read(project) as view:
            variables = read_only_variables(self._load(view, axis).dictionary)
        return [v for v in variables if group is None or v.group.casefold() == group.casefold()]

    def transferable(self, project: str, axis: str, group: str | None = None) -> list[Variable]:
        """The objects a compare with the drive covers (optionally one UI group): what a drive source must read."""
        with self.store.read(project) as view:
            variables = self._load(view, axis).transferable()
        return [v for v in variables if group is None or v.group.casefold() == group.casefold()]

    def axis_values(self, edit: ProjectEdit, axis: str) -> AxisValues:
        """The parsed value files of an axis inside an edit (for motor selection, templates, DCF export)."""
        return self._load(edit, axis)

    def _load(self, edit: ProjectEdit, axis: str) -> AxisValues:
        chosen = edit.axis(axis)
        return AxisValues.load(edit.axis_directory(axis), self.dictionary(chosen), chosen.node_id)


def read_only_variables(dictionary: ObjectDictionary) -> list[Variable]:
    """Readable entries nobody can write: the drive changes them by itself, no download or restore sets them."""
    return [v for v in dictionary.variables() if v.access.readable and not v.access.writable]


def _keeping(edit: ProjectEdit, reason: str | None) -> contextlib.AbstractContextManager[None]:
    return keeping(edit, reason) if reason else contextlib.nullcontext()


def parameter_row(values: AxisValues, variable: Variable) -> ParameterRow:
    return ParameterRow(
        variable,
        values.value(variable),
        values.default(variable),
        values.file_of(variable),
        values.editable_reason(variable),
    )
