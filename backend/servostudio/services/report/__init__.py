"""The commissioning report (issue #16 item 5, docs/report.md): one standalone, printable HTML file per project or
per axis, generated from the project's files alone — it needs no drive and no server, and opens offline."""

from __future__ import annotations

from servostudio.services.audit import AuditLog
from servostudio.services.projects import ProjectService
from servostudio.services.report.collect import AxisRecord, ProjectRecord, collect
from servostudio.services.report.page import document


def report_html(projects: ProjectService, project: str, axis: str | None = None, audit: AuditLog | None = None) -> str:
    """The report of a project (every axis) or of one axis; ``audit`` adds who changed the settings when."""
    return document(collect(projects, project, axis, audit))


def report_file_name(project: str, axis: str | None = None) -> str:
    """The name a download of the report gets."""
    return f"{project}-{axis}-report.html" if axis else f"{project}-report.html"


__all__ = ["AxisRecord", "ProjectRecord", "collect", "report_file_name", "report_html"]
