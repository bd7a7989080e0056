"""Projects and axes: the project store, offline parameter editing, compare, motor catalog, Device Config templates,
archives and DCF export; with live drives in the subpackage ``live``. See docs/projects.md."""

from servostudio.services.projects.archive import ArchiveLimits
from servostudio.services.projects.compare import CompareRow, DefaultValues, ParameterSource, ProjectValues, compare
from servostudio.services.projects.errors import (
    ArchiveError,
    ConflictError,
    DriveMismatch,
    DriveUnavailable,
    FileFormatError,
    InvalidName,
    ParameterRefused,
    ProjectError,
    ProjectExists,
    ProjectNotFound,
    ValidationError,
)
from servostudio.services.projects.model import Axis, Bus, Project
from servostudio.services.projects.motors import Motor, MotorCatalog
from servostudio.services.projects.parameters import ParameterChange, ParameterRow, ParameterService
from servostudio.services.projects.service import AxisChoice, ProjectService
from servostudio.services.projects.store import ProjectStore, Snapshot
from servostudio.services.projects.templates import TEMPLATES, ApplicationTemplate, templates_for

__all__ = [
    "TEMPLATES",
    "ApplicationTemplate",
    "ArchiveError",
    "ArchiveLimits",
    "Axis",
    "AxisChoice",
    "Bus",
    "CompareRow",
    "ConflictError",
    "DefaultValues",
    "DriveMismatch",
    "DriveUnavailable",
    "FileFormatError",
    "InvalidName",
    "Motor",
    "MotorCatalog",
    "ParameterChange",
    "ParameterRefused",
    "ParameterRow",
    "ParameterService",
    "ParameterSource",
    "Project",
    "ProjectError",
    "ProjectExists",
    "ProjectNotFound",
    "ProjectService",
    "ProjectStore",
    "ProjectValues",
    "Snapshot",
    "ValidationError",
    "compare",
    "templates_for",
]
