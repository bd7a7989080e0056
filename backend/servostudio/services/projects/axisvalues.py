"""The parameter values a project holds for one axis, in the device's parameter files.

The device profile names the files and the SaveType each holds (XtrapulsPac: DRIVEPAR -> DRIVEPAR.TXT,
USER_PAR -> USER_PAR.TXT; CD1-k and encoTRive: DRIVEPAR.TXT only). The drive applies them in that order (XtrapulsPac
loads USER_PAR.TXT after DRIVEPAR.TXT with 0x1011 'lusr'), so when two files hold an object the later one gives the
project value; writing an object removes it from the other files so that the file its SaveType names is the only one.
Entries for objects the dictionary does not know are kept untouched (e.g. a backup from newer firmware).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

from servostudio.formats.objectfile import (
    ObjectEntry,
    ObjectFileError,
)
from servostudio.formats.parameterfile import format_drive_file, parse_drive_file
from servostudio.formats.textfile import FILE_ENCODING
from servostudio.od import ObjectDictionary, OutOfRange, SaveType, Variable, WrongType
from servostudio.services.projects.devices import parameter_files
from servostudio.services.projects.errors import FileFormatError, ParameterRefused
from servostudio.services.projects.parameter_values import (
    BadValue,
    Value,
    coerce,
    from_file_value,
    normalize,
    to_file_value,
)
from servostudio.services.projects.store import ProjectEdit

Key = tuple[int, int]


def editable_reason(variable: Variable, files: Mapping[str, SaveType]) -> str | None:
    """Why ``variable`` cannot be edited in a project whose axis has these parameter files, or None when it can."""
    if not variable.access.writable:
        return f"{variable.label} is read-only ({variable.access.value})"
    if variable.save_type not in files.values():
        return (
            f"{variable.label} is not saved in a drive file (save type {variable.save_type.value}); "
            "it can only be written to a live drive"
        )
    if variable.data_type.is_binary:
        return f"{variable.label}: {variable.data_type.name} values cannot be edited offline"
    return None


@dataclass
class AxisValues:
    """The parameter files of one axis, parsed; changes are staged and written together by :meth:`commit`."""

    dictionary: ObjectDictionary
    node_id: int
    files: dict[str, dict[Key, ObjectEntry]] = field(default_factory=dict)
    changed: set[str] = field(default_factory=set)

    @classmethod
    def load(cls, directory: Path, dictionary: ObjectDictionary, node_id: int, strict: bool = False) -> AxisValues:
        """The axis's files parsed; each value must be of its object's type, and with ``strict`` (files from
        outside, such as an archive) pass every rule of the editor, ranges included (`check_as_editor`)."""
        values = cls(dictionary, node_id)
        check = values.check_as_editor if strict else values._check_entry
        for file_name in values.parameter_files:
            path = directory / file_name
            text = path.read_text(encoding=FILE_ENCODING) if path.is_file() else ""
            try:
                entries = parse_drive_file(file_name, text, str(path), check)
            except ObjectFileError as error:
                raise FileFormatError(error.file, error.line, error.reason) from None
            values.files[file_name] = {(entry.index, entry.sub): entry for entry in entries}
        return values

    @property
    def parameter_files(self) -> Mapping[str, SaveType]:
        return parameter_files(self.dictionary.device)

    def editable_reason(self, variable: Variable) -> str | None:
        return editable_reason(variable, self.parameter_files)

    def transferable(self) -> list[Variable]:
        """The objects a drive and the project exchange (download writes them, upload reads them): editable offline
        and readable from the drive, in dictionary order."""
        return [
            variable
            for variable in self.dictionary.variables()
            if variable.access.readable and self.editable_reason(variable) is None
        ]

    # ---- reading ---------------------------------------------------------------------------------------------

    def explicit(self, variable: Variable) -> Value | None:
        """The value the project files set for ``variable`` (the file applied last wins), or None."""
        for file_name in list(self.parameter_files)[::-1]:
            entry = self.files[file_name].get(variable.key)
            if entry is not None:
                return from_file_value(variable, entry.value)
        return None

    def default(self, variable: Variable) -> Value | None:
        return normalize(variable, variable.default_for(self.node_id))

    def value(self, variable: Variable) -> Value | None:
        """The project value: what the files set, else the dictionary default (what a fresh drive would hold)."""
        explicit = self.explicit(variable)
        return normalize(variable, explicit) if explicit is not None else self.default(variable)

    def file_of(self, variable: Variable) -> str | None:
        return next((name for name in list(self.parameter_files)[::-1] if variable.key in self.files[name]), None)

    # ---- changing --------------------------------------------------------------------------------------------

    def resolve(self, address: str) -> Variable:
        try:
            return self.dictionary.find(address)
        except KeyError as error:
            raise ParameterRefused(str(error.args[0])) from None

    def stage(self, variable: Variable, raw: object) -> Value:
        """Check ``raw`` exactly as an online write would, then stage it in the file its SaveType names."""
        reason = self.editable_reason(variable)
        if reason:
            raise ParameterRefused(reason)
        try:
            value = coerce(variable, raw)
            variable.check(value)
            stored = to_file_value(variable, value)
        except (BadValue, WrongType, OutOfRange) as error:
            raise ParameterRefused(str(error)) from None
        target = next(name for name, save_type in self.parameter_files.items() if save_type is variable.save_type)
        for file_name, entries in self.files.items():
            if file_name != target and entries.pop(variable.key, None) is not None:
                self.changed.add(file_name)
        self.files[target][variable.key] = ObjectEntry(variable.index, variable.subindex, stored)
        self.changed.add(target)
        return normalize(variable, value)  # type: ignore[return-value]

    def unset(self, variable: Variable) -> None:
        """Drop the project's value for ``variable``, so it follows the dictionary default again."""
        for file_name, entries in self.files.items():
            if entries.pop(variable.key, None) is not None:
                self.changed.add(file_name)

    def commit(self, edit: ProjectEdit, axis: str) -> None:
        """Render every changed file first (so a value the file format cannot hold writes nothing), then write."""
        texts: dict[str, str] = {}
        for file_name in sorted(self.changed):
            try:
                texts[file_name] = format_drive_file(file_name, self.files[file_name].values())
            except ValueError as error:
                raise ParameterRefused(f"{file_name}: {error}") from None
        for file_name, text in texts.items():
            edit.write_axis_file(axis, file_name, text.encode(FILE_ENCODING))
        self.changed.clear()

    def check_as_editor(self, entry: ObjectEntry) -> str | None:
        """Why the editor would refuse this entry's value (`stage`: an object it may edit, a value of the object's
        type within its range), or None; an object the dictionary does not know is kept, as the editor keeps it."""
        variable = self.dictionary.get(entry.index, entry.sub)
        if variable is None:
            return None
        reason = self.editable_reason(variable)
        if reason is not None:
            return reason
        try:
            variable.check(from_file_value(variable, entry.value))
        except (BadValue, WrongType, OutOfRange) as error:
            return str(error)
        return None

    def _check_entry(self, entry: ObjectEntry) -> str | None:
        variable = self.dictionary.get(entry.index, entry.sub)
        if variable is None:
            return None
        try:
            from_file_value(variable, entry.value)
        except BadValue as error:
            return str(error)
        return None
