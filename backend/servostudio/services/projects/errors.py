"""Errors of the project service.

Each error carries a message a user can act on, and the kind of its category class (``servostudio.errors``) gives
its HTTP status and CLI exit code, so callers never have to parse messages.
"""

from __future__ import annotations

from pathlib import Path

from servostudio.errors import Conflict, InvalidInput, NotFound, ServoStudioError, TooLarge, Unavailable


class ProjectError(ServoStudioError):
    """Base class: a project operation was refused; nothing was written."""


class ProjectNotFound(NotFound, ProjectError):
    """The project, axis, motor or template named by the caller does not exist."""


class ProjectExists(Conflict, ProjectError):
    """Creating or renaming would overwrite an existing project or axis."""


class InvalidName(InvalidInput, ProjectError):
    """A project, axis or motor name cannot be used as a directory or file name."""


class ValidationError(InvalidInput, ProjectError):
    """The requested change breaks a project rule (node ID range, unique node IDs, unknown bus, ...)."""


class ParameterRefused(InvalidInput, ProjectError):
    """An offline parameter write was refused: unknown object, read-only, not saved in a drive file, out of range."""


class ConflictError(Conflict, ProjectError):
    """The project changed since the caller read it (optimistic revision check failed)."""

    def __init__(self, project: str, expected: str, actual: str) -> None:
        super().__init__(
            f"project '{project}' was changed by someone else (expected revision {expected}, now {actual});"
            " reload it and apply the change again"
        )
        self.expected = expected
        self.actual = actual


class FileFormatError(InvalidInput, ProjectError):
    """A project, motor or template text file is malformed: names the file, the line and the reason."""

    def __init__(self, file: Path | str, line: int, reason: str) -> None:
        super().__init__(f"{file}:{line}: {reason}")
        self.file = str(file)
        self.line = line
        self.reason = reason


class ArchiveError(InvalidInput, ProjectError):
    """An archive cannot be unpacked safely (path traversal, link, oversized member, zip bomb, not a zip)."""


class ArchiveTooLarge(TooLarge, ArchiveError):
    """An uploaded archive is larger than the archive limits allow; it was refused before it was unpacked."""


class DriveMismatch(Conflict, ProjectError):
    """The drive found at an axis's bus and node is not the device the project expects (or not identifiable)."""


class DriveUnavailable(Unavailable, ProjectError):
    """An axis's drive cannot be reached: its bus is not connected or the node does not answer."""
