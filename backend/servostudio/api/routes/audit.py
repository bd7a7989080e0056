"""The audit log: who wrote what to drives and projects, every motion start and stop — filtered, paged, exported.

Filters: ``axis`` (``BUS:NODE``), ``user``, ``project``, ``action``, ``since`` / ``until`` (ISO 8601 or an age such as
``2h``).  ``GET /api/audit`` pages newest first; ``GET /api/audit/export?format=csv|jsonl`` gives every matching
entry, oldest first, as a download.  The format is in ``docs/security.md`` (Audit log).
"""

from __future__ import annotations

from typing import Annotated, Any

from fastapi import APIRouter, Depends, Query
from fastapi.responses import StreamingResponse
from pydantic import BaseModel, Field

from servostudio.api.deps import Server
from servostudio.api.security import Requires
from servostudio.services.audit import MAX_PAGE, AuditLog, AuditQuery, parse_time
from servostudio.services.users import Level

router = APIRouter(tags=["audit"])
MEDIA_TYPES = {"csv": "text/csv", "jsonl": "application/x-ndjson"}


class AuditPageModel(BaseModel):
    total: int = Field(description="entries matching the filters")
    offset: int
    limit: int
    entries: list[dict[str, Any]] = Field(
        description="newest first: {seq, time, user, client, action, axis, project, project_axis, object, name, "
        "old, new, result, detail}"
    )


def audit_log(state: Server) -> AuditLog:
    return state.audit


def audit_query(
    axis: Annotated[str | None, Query(description="BUS:NODE, e.g. sim:1")] = None,
    user: str | None = None,
    project: str | None = None,
    action: Annotated[str | None, Query(description="drive_write, project_write, arm, enable, stop, …")] = None,
    since: Annotated[str | None, Query(description="ISO 8601 time or an age (30m, 2h, 7d)")] = None,
    until: Annotated[str | None, Query(description="ISO 8601 time or an age")] = None,
    offset: Annotated[int, Query(ge=0)] = 0,
    limit: Annotated[int, Query(ge=1, le=MAX_PAGE)] = 100,
) -> AuditQuery:
    """The filters and the page the query string names."""
    start, end = (parse_time(text) if text else None for text in (since, until))
    return AuditQuery(axis, user, project, action, start, end, offset, limit)


Audit = Annotated[AuditLog, Depends(audit_log)]
Filters = Annotated[AuditQuery, Depends(audit_query)]


@router.get(
    "/audit",
    response_model=AuditPageModel,
    summary="Audit log entries, newest first (filters: axis, user, project, action, since, until; paging)",
    dependencies=[Requires(Level.EXPERT)],
)
def list_entries(audit: Audit, query: Filters) -> dict:
    page = audit.entries(query)
    return {"total": page.total, "offset": query.offset, "limit": query.limit, "entries": page.entries}


@router.get(
    "/audit/export",
    response_class=StreamingResponse,
    summary="Every matching audit entry, oldest first, as CSV or JSON lines",
    dependencies=[Requires(Level.EXPERT)],
    responses={200: {"content": {media: {} for media in MEDIA_TYPES.values()}}},
)
def export_entries(
    audit: Audit, query: Filters, form: Annotated[str, Query(alias="format", pattern="^(csv|jsonl)$")] = "jsonl"
) -> StreamingResponse:
    disposition = {"Content-Disposition": f'attachment; filename="audit.{form}"'}
    return StreamingResponse(audit.export(query, form), media_type=MEDIA_TYPES[form], headers=disposition)
