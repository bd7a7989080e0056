"""Tool-side identification of a drive's mechanics (docs/identification.md).

``POST …/identification`` starts the experiment as a job (202, operation ``identification``; ``progress`` events on
/api/ws/events; cancel = quick stop). What refuses it comes back before anything is written: 422 options out of
range or a profile beyond the position window, 409 without the axis's armed controller (``X-Servo-Client``). The
job's result is the CLI's pinned JSON (``servostudio identify``), its ``identified`` in auto-tuning's keys.
"""

from __future__ import annotations

from fastapi import APIRouter, status

from servostudio.api.deps import Jobs, Motion, NodeDrive, OpenBus
from servostudio.api.errors import error_responses
from servostudio.api.routes.comm_models import JobModel
from servostudio.api.routes.drives import DRIVE_ERRORS
from servostudio.api.routes.identification_models import IdentificationStart
from servostudio.api.security import Requires
from servostudio.errors import ErrorKind
from servostudio.services import identification
from servostudio.services.users import Level

PATH = "/buses/{bus}/nodes/{node}/identification"
router = APIRouter(tags=["procedures"])


@router.post(
    PATH,
    response_model=JobModel,
    status_code=status.HTTP_202_ACCEPTED,
    summary="Identify inertia, friction and load with the tool's own experiment, as a job (cancel = quick stop)",
    responses=error_responses(*DRIVE_ERRORS, ErrorKind.INVALID_INPUT),
    dependencies=[Requires(Level.EXPERT)],  # the motor turns, like auto-tuning (docs/security.md)
)
def start_identification(
    body: IdentificationStart, connection: OpenBus, drive: NodeDrive, jobs: Jobs, motion: Motion
) -> dict:
    return identification.start(jobs, motion, connection, drive, body.request()).as_dict()
