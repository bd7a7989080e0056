"""One entry point for the API and the CLI: the store plus everything done to a project's axes."""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

from servostudio.drive.profiles import profile_for
from servostudio.formats.sequence import SequenceFileError, parse_sequence_text
from servostudio.formats.textfile import FILE_ENCODING
from servostudio.od import ObjectDictionary, Variable, parse_dictionary
from servostudio.services import sequence_buffer
from servostudio.services.audit import AuditLog, ProjectAudit
from servostudio.services.projects import layout
from servostudio.services.projects.archive import DEFAULT_LIMITS, ArchiveLimits, archive_project, unarchive_project
from servostudio.services.projects.axisvalues import AxisValues
from servostudio.services.projects.dcf import ConfiguredValues, configured_values, export_dcf
from servostudio.services.projects.errors import FileFormatError
from servostudio.services.projects.model import Project
from servostudio.services.projects.motors import BUILTIN_MOTORS_DIR, MotorCatalog
from servostudio.services.projects.motorselect import apply_motor
from servostudio.services.projects.parameter_values import Value
from servostudio.services.projects.parameters import DictionaryLibrary, ParameterChange, ParameterService, parameter_row
from servostudio.services.projects.revisions import KeptRevision, keeping, kept, restore
from servostudio.services.projects.store import UNRECORDED, ProjectStore, Snapshot
from servostudio.services.projects.templates import ApplicationTemplate, template
from servostudio.services.projects.validation import validate_project


@dataclass(frozen=True)
class ValueChange:
    """One project value a change replaces: the object, its value before and after."""

    variable: Variable
    old: Value | None
    new: Value | None


@dataclass(frozen=True)
class DcfImport:
    """Result of a DCF import (or of its preview): the objects set, the project values that change (old, new), and
    the configured values the project cannot hold (and why)."""

    change: ParameterChange
    skipped: list[str]
    changes: list[ValueChange]


@dataclass(frozen=True)
class AxisChoice:
    """Result of selecting a motor or a template: the objects set, what could not be reproduced, the new state."""

    change: ParameterChange
    notes: list[str]
    snapshot: Snapshot


class ProjectService:
    def __init__(
        self,
        root: Path,
        library: DictionaryLibrary,
        motors_dir: Path = BUILTIN_MOTORS_DIR,
        audit: AuditLog | None = None,
    ) -> None:
        self.store = ProjectStore(root, library, ProjectAudit(audit) if audit is not None else UNRECORDED)
        self.library = library
        self.parameters = ParameterService(self.store, library)
        self.motors = MotorCatalog(motors_dir, Path(root) / layout.USER_MOTORS_DIR)

    def select_motor(self, project: str, axis: str, reference: str, expected_revision: str | None = None) -> AxisChoice:
        """Record the catalog motor for the axis and set its values and their consequences (all or nothing)."""
        motor = self.motors.get(reference)
        with self.store.edit(project, expected_revision) as edit:
            values = self.parameters.axis_values(edit, axis)
            applied = apply_motor(values, motor)
            values.commit(edit, axis)
            self.store.replace_axis(edit, replace(edit.axis(axis), motor=motor.reference))
        rows = [parameter_row(values, variable) for variable in applied.changed]
        return AxisChoice(ParameterChange(rows, edit.revision), applied.notes, Snapshot(edit.project, edit.revision))

    def apply_template(self, project: str, axis: str, key: str, expected_revision: str | None = None) -> AxisChoice:
        """Set the template's mode and I/O functions and record it as the axis's application (all or nothing)."""
        with self.store.edit(project, expected_revision) as edit:
            chosen = template(key, edit.axis(axis).device)
            values = self.parameters.axis_values(edit, axis)
            touched = []
            for setting in chosen.settings:
                variable = values.resolve(f"0x{setting.index:04X},{setting.sub}")
                values.stage(variable, setting.value)
                touched.append(variable)
            values.commit(edit, axis)
            self.store.replace_axis(edit, replace(edit.axis(axis), application=chosen.key))
        rows = [parameter_row(values, variable) for variable in touched]
        return AxisChoice(ParameterChange(rows, edit.revision), [], Snapshot(edit.project, edit.revision))

    def application(self, project: str, axis: str) -> ApplicationTemplate | None:
        chosen = self.store.open(project).project.axis(axis)
        return template(chosen.application, chosen.device) if chosen and chosen.application else None

    def dcf(self, project: str, axis: str) -> str:
        with self.store.read(project) as view:
            chosen = view.axis(axis)
            values = self.parameters.axis_values(view, axis)
            eds_text = values.dictionary.source.read_text(encoding="latin-1")
            return export_dcf(eds_text, view.project, chosen, values)

    def import_dcf(
        self, project: str, axis: str, text: str, file_name: str, expected_revision: str | None = None
    ) -> DcfImport:
        """Set the axis's offline values to what a DCF configures (all or nothing, checked as offline edits); the
        configured values the project cannot hold are listed in the result, and the project as it was is kept as a
        revision. The DCF comes as its text and the name the user knows it by, so its errors name that file and
        never a server path."""
        configuration = parse_dictionary(text, file_name)
        kept = f"import of {Path(file_name).name} into axis {axis}"  # the values it replaces stay restorable
        with self.store.edit(project, expected_revision) as edit, keeping(edit, kept):
            values = self.parameters.axis_values(edit, axis)
            configured, changes = _configure(configuration, values)
            values.commit(edit, axis)
        rows = [parameter_row(values, variable) for variable, _ in configured.values]
        return DcfImport(ParameterChange(rows, edit.revision), configured.skipped, changes)

    def preview_dcf(self, project: str, axis: str, text: str, file_name: str) -> DcfImport:
        """What :meth:`import_dcf` would do, checked the same way, without writing: the confirmation shows it."""
        configuration = parse_dictionary(text, file_name)
        with self.store.read(project) as view:
            values = self.parameters.axis_values(view, axis)
            configured, changes = _configure(configuration, values)
        rows = [parameter_row(values, variable) for variable, _ in configured.values]
        return DcfImport(ParameterChange(rows, view.revision), configured.skipped, changes)

    def revisions(self, project: str) -> list[KeptRevision]:
        """The project's kept revisions, newest first (what changes that replaced many values overwrote)."""
        with self.store.read(project) as view:
            return kept(view.directory)

    def restore_revision(self, project: str, revision: str, expected_revision: str | None = None) -> Snapshot:
        """Make the project what it was at a kept revision; the state it replaces is kept in turn (undo)."""
        with self.store.edit(project, expected_revision) as edit, keeping(edit, f"restore of revision {revision}"):
            restore(edit, revision, lambda chosen: validate_project(chosen, self.library.devices()))
        return Snapshot(edit.project, edit.revision)

    def archive(self, project: str, destination: Path) -> Path:
        return archive_project(self.store, project, destination)

    def unarchive(self, source: Path, new_name: str | None = None, limits: ArchiveLimits = DEFAULT_LIMITS) -> Snapshot:
        return unarchive_project(self.store, source, new_name, limits, verify=self.check_axis_files)

    def check_axis_files(self, directory: Path, project: Project) -> None:
        """Check every axis's object files by the editor's rules (ranges included) and its sequence file; raise
        :class:`FileFormatError` naming the first bad file and line."""
        for axis in project.axes:
            axis_directory = directory / axis.name
            AxisValues.load(axis_directory, self.parameters.dictionary(axis), axis.node_id, strict=True)
            _check_sequence_buffer_file(axis_directory, axis.device, self.parameters.dictionary(axis))
            sequence = axis_directory / layout.SEQUENCE
            if sequence.is_file():
                try:
                    parse_sequence_text(sequence.read_text(encoding=FILE_ENCODING), str(sequence))
                except SequenceFileError as error:
                    first = error.issues[0]
                    raise FileFormatError(sequence, first.line, str(first).partition(": ")[2]) from None


def _check_sequence_buffer_file(directory: Path, device: str, dictionary: ObjectDictionary) -> None:
    """A TTA-PRO's TTASEQ.TXT, checked as a restore checks it (before anything is written)."""
    profile = profile_for(device)
    path = directory / profile.sequence_buffer.file if profile.sequence_buffer is not None else None
    if path is None or not path.is_file():
        return
    try:
        sequence_buffer.parse_table(profile, dictionary, path.read_text(encoding=FILE_ENCODING), str(path))
    except sequence_buffer.SequenceTableInvalid as error:
        raise FileFormatError(path, error.line, error.reason) from None


def _configure(configuration: ObjectDictionary, values: AxisValues) -> tuple[ConfiguredValues, list[ValueChange]]:
    """Stage a DCF's configured values on the axis's values (each checked as an offline edit); return them and the
    project values they change, old and new."""
    configured = configured_values(configuration, values)
    changes = []
    for variable, value in configured.values:
        old = values.value(variable)
        values.stage(variable, value)
        if values.value(variable) != old:
            changes.append(ValueChange(variable, old, values.value(variable)))
    return configured, changes
