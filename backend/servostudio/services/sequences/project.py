"""The project's SEQUENCE.TXT of an axis: the source of truth the editor edits offline and online.

A write is checked by the file reader first (nothing is written from a file with an error) and lands atomically
through the project store, which journals it (audit log) and refuses it when the project changed since the revision
the caller read.
"""

from __future__ import annotations

from servostudio.drive.profiles import profile_for
from servostudio.formats.textfile import FILE_ENCODING
from servostudio.services.projects import ProjectService
from servostudio.services.projects.layout import SEQUENCE
from servostudio.services.sequences.files import parse
from servostudio.services.sequences.memory import NoSequences


def read_text(service: ProjectService, project: str, axis: str) -> tuple[str, str]:
    """The axis's SEQUENCE.TXT (empty when it has none yet) and the project's revision."""
    with service.store.read(project) as view:
        _check_device(view.axis(axis).device, axis)
        path = view.axis_directory(axis) / SEQUENCE
        text = path.read_text(encoding=FILE_ENCODING) if path.is_file() else ""
        return text, view.revision


def write_text(service: ProjectService, project: str, axis: str, text: str, revision: str | None) -> str:
    """Check, then write the axis's SEQUENCE.TXT; returns the new revision."""
    parse(text)
    with service.store.edit(project, revision) as edit:
        _check_device(edit.axis(axis).device, axis)
        edit.write_axis_file(axis, SEQUENCE, text.encode(FILE_ENCODING))
    return edit.revision


def _check_device(device: str, axis: str) -> None:
    if not profile_for(device).has_sequences:
        raise NoSequences(f"axis {axis}: a {device} has no sequence mode (no SEQUENCE.TXT)")
