"""Procedures of a drive: auto-phasing, motor phasing, current-loop and current-limit calculation, auto-tuning.

``GET …/procedures`` lists them with their preconditions read from the drive now. ``POST …/procedures/{name}``
starts one as a job (202, operation ``procedure:<name>``; ``progress`` events on /api/ws/events; cancel = abort);
what refuses it comes back before anything is written: 404 unknown procedure, 422 bad options, 409 unmet
precondition with the manual's reason or a moving procedure without the axis's armed controller (``X-Servo-Client``).
The job's result is the CLI's pinned JSON (docs/commissioning.md).
"""

from __future__ import annotations

from fastapi import APIRouter, status

from servostudio.api.deps import Jobs, Motion, NodeDrive, OpenBus, Projects
from servostudio.api.errors import error_responses
from servostudio.api.routes.comm_models import JobModel
from servostudio.api.routes.drives import DRIVE_ERRORS
from servostudio.api.routes.procedure_models import ProcedureModel, ProcedureStart, UndoRequest, UndoResult
from servostudio.api.security import Requires
from servostudio.errors import ErrorKind
from servostudio.services.procedures import ProcedureService, ResultStore, describe
from servostudio.services.users import Level

LIVE = "/buses/{bus}/nodes/{node}/procedures"
SAVED = "/projects/{project}/axes/{axis}/procedures"
router = APIRouter(tags=["procedures"])


def _service(projects: Projects) -> ProcedureService:
    return ProcedureService(ResultStore(projects.store))


@router.get(
    LIVE,
    response_model=list[ProcedureModel],
    summary="The drive's procedures, their status and their preconditions read from the drive now",
    responses=error_responses(*DRIVE_ERRORS),
    dependencies=[Requires(Level.OPERATOR)],
)
def list_procedures(drive: NodeDrive) -> list[dict]:
    return describe(drive)


@router.post(
    LIVE + "/auto_tuning/undo",
    response_model=UndoResult,
    summary="Write an auto-tuning result's `before` gains back (checked completely before any write)",
    responses=error_responses(*DRIVE_ERRORS),
    dependencies=[Requires(Level.EXPERT)],  # phasing and tuning are the Expert's (docs/security.md)
)
def undo_tuning(body: UndoRequest, drive: NodeDrive, projects: Projects) -> dict:
    return _service(projects).undo(drive, body.gains)


@router.post(
    LIVE + "/{name}",
    response_model=JobModel,
    status_code=status.HTTP_202_ACCEPTED,
    summary="Start a procedure as a job (refusals before anything is written; cancel the job to abort it)",
    responses=error_responses(*DRIVE_ERRORS),
    dependencies=[Requires(Level.EXPERT)],
)
def start_procedure(
    name: str, body: ProcedureStart, connection: OpenBus, drive: NodeDrive, jobs: Jobs, motion: Motion,
    projects: Projects,
) -> dict:  # fmt: skip
    return _service(projects).start(jobs, motion, connection, drive, name, body.request()).as_dict()


@router.get(
    SAVED,
    response_model=list[dict],
    summary="The procedure results saved under the axis, newest first",
    responses=error_responses(ErrorKind.NOT_FOUND),
    dependencies=[Requires(Level.OPERATOR)],
)
def list_saved(project: str, axis: str, projects: Projects) -> list[dict]:
    return _service(projects).saved(project, axis)
