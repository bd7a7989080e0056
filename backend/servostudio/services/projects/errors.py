"""Errors of the project service.

Each error carries a message a user can act on; the API maps the classes to HTTP status codes and the CLI to exit
codes, so callers never have to parse messages.
"""

from __future__ import annotations

from pathlib import Path


class ProjectError(Exception):
    """Base class: a project operation was refused; nothing was written."""


class ProjectNotFound(ProjectError):
    """The project, axis, motor or template named by the caller does not exist."""


class ProjectExists(ProjectError):
    """Creating or renaming would overwrite an existing project or axis."""


class InvalidName(ProjectError):
    """A project, axis or motor name cannot be used as a directory or file name."""


class ValidationError(ProjectError):
    """The requested change breaks a project rule (node ID range, unique node IDs, unknown bus, ...)."""


class ParameterRefused(ProjectError):
    """An offline parameter write was refused: unknown object, read-only, not saved in a drive file, out of range."""


class ConflictError(ProjectError):
    """The project changed since the caller read it (optimistic revision check failed)."""

    def __init__(self, project: str, expected: str, actual: str) -> None:
        super().__init__(
            f"project '{project}' was changed by someone else (expected revision {expected}, now {actual});"
            " reload it and apply the change again"
        )
        self.expected = expected
        self.actual = actual


class FileFormatError(ProjectError):
    """A project, motor or template text file is malformed: names the file, the line and the reason."""

    def __init__(self, file: Path | str, line: int, reason: str) -> None:
        super().__init__(f"{file}:{line}: {reason}")
        self.file = str(file)
        self.line = line
        self.reason = reason


class ArchiveError(ProjectError):
    """An archive cannot be unpacked safely (path traversal, link, oversized member, zip bomb, not a zip)."""


class DriveMismatch(ProjectError):
    """The drive found at an axis's bus and node is not the device the project expects (or not identifiable)."""


class DriveUnavailable(ProjectError):
    """An axis's drive cannot be reached: its bus is not connected or the node does not answer."""
