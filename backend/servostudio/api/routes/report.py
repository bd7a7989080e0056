"""The commissioning report (docs/report.md) as a download: one standalone HTML file of a project or of one axis,
generated from the project's files (``services/report``), the same file ``servostudio report`` writes.

Reading a project is Operator level, so is its report; the audit log's history of who changed the project is in it
only for callers who may read the audit log (Expert and above), for the others the report says it is not shown.
"""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Query, Response

from servostudio.api.deps import Caller, Projects, Server
from servostudio.api.downloads import attachment
from servostudio.api.errors import error_responses
from servostudio.api.security import Requires
from servostudio.errors import ErrorKind
from servostudio.services.report import report_file_name, report_html
from servostudio.services.users import Level

router = APIRouter(tags=["projects"])
#: the level the audit log needs (routes/audit.py): below it the report leaves the history out
AUDIT_LEVEL = Level.EXPERT


@router.get(
    "/projects/{project}/report",
    response_class=Response,
    summary="The commissioning report of the project (or of one axis) as a standalone HTML download",
    responses={**error_responses(ErrorKind.NOT_FOUND), 200: {"content": {"text/html": {}}}},
    dependencies=[Requires(Level.OPERATOR)],
)
def get_report(
    project: str,
    projects: Projects,
    state: Server,
    user: Caller,
    axis: Annotated[str | None, Query(description="one axis of the project (default: every axis)")] = None,
) -> Response:
    audit = state.audit if user.level.at_least(AUDIT_LEVEL) else None
    html = report_html(projects, project, axis, audit)
    return Response(html, media_type="text/html; charset=utf-8", headers=attachment(report_file_name(project, axis)))
