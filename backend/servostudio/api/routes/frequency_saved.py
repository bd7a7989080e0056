"""Frequency responses saved in a project under their axis (the Bode page's sets to overlay and compare): list,
the full result, the pinned CSV, a standalone HTML file, delete.  Measuring is ``frequency.py``'s route; a
measurement given a project and axis is saved there by ``services/frequency/store.py``.

Reading is the Operator's (like saved captures); deleting changes the project's records and needs Expert, as
deleting a saved capture does (docs/security.md).
"""

from __future__ import annotations

import math
from typing import Any

from fastapi import APIRouter, Query, Response, status

from servostudio.api.deps import Projects
from servostudio.api.downloads import file_download as download
from servostudio.api.errors import error_responses
from servostudio.api.routes.frequency_saved_models import SavedFrequencyResult, SavedFrequencySummary
from servostudio.api.security import Requires
from servostudio.errors import ErrorKind
from servostudio.services.frequency.saved import SavedFrequency
from servostudio.services.users import Level

SAVED = "/projects/{project}/axes/{axis}/frequency"
ERRORS = (ErrorKind.NOT_FOUND, ErrorKind.INVALID_INPUT)
#: at most this many results overlaid in one HTML file
MAX_COMPARE = 8
router = APIRouter(tags=["frequency"])


@router.get(
    SAVED,
    response_model=list[SavedFrequencySummary],
    summary="The frequency responses saved under the axis, newest first (a damaged one names its file in `error`)",
    responses=error_responses(*ERRORS),
    dependencies=[Requires(Level.OPERATOR)],
)
def list_saved(project: str, axis: str, projects: Projects) -> list[dict[str, Any]]:
    return SavedFrequency(projects.store).list(project, axis)


@router.get(
    SAVED + "/{name}",
    response_model=SavedFrequencyResult,
    summary="A saved frequency response with its points (422 names the file and line of a damaged one)",
    responses=error_responses(*ERRORS),
    dependencies=[Requires(Level.OPERATOR)],
)
def open_saved(project: str, axis: str, name: str, projects: Projects) -> dict[str, Any]:
    result = SavedFrequency(projects.store).open(project, axis, name)
    return {**result, "points": [_json_point(point) for point in result["points"]]}


@router.get(
    SAVED + "/{name}/csv",
    response_class=Response,
    summary="A saved frequency response as CSV: freq_hz,magnitude_db,phase_deg,coherence after # comment lines",
    responses={**error_responses(*ERRORS), 200: {"content": {"text/csv": {}}}},
    dependencies=[Requires(Level.OPERATOR)],
)
def saved_csv(project: str, axis: str, name: str, projects: Projects) -> Response:
    return download(SavedFrequency(projects.store).csv(project, axis, name), "text/csv", f"{name}.csv")


@router.get(
    SAVED + "/{name}/html",
    response_class=Response,
    summary="A saved frequency response (and those named in `compare`, overlaid) as a standalone HTML file",
    responses={**error_responses(*ERRORS), 200: {"content": {"text/html": {}}}},
    dependencies=[Requires(Level.OPERATOR)],
)
def saved_html(
    project: str,
    axis: str,
    name: str,
    projects: Projects,
    compare: list[str] = Query(default=[], max_length=MAX_COMPARE, description="saved results to overlay"),  # noqa: B008
) -> Response:
    document = SavedFrequency(projects.store).html(project, axis, name, compare)
    return download(document, "text/html", f"{name}.html")


@router.delete(
    SAVED + "/{name}",
    status_code=status.HTTP_204_NO_CONTENT,
    response_class=Response,
    summary="Delete a saved frequency response (changing the project's records needs Expert, like the project)",
    responses=error_responses(*ERRORS),
    dependencies=[Requires(Level.EXPERT)],
)
def delete_saved(project: str, axis: str, name: str, projects: Projects) -> Response:
    SavedFrequency(projects.store).delete(project, axis, name)
    return Response(status_code=status.HTTP_204_NO_CONTENT)


def _json_point(point: dict[str, float]) -> dict[str, float | None]:
    """JSON has no NaN: a value that is not finite (coherence not estimated) is null."""
    return {key: value if math.isfinite(value) else None for key, value in point.items()}
