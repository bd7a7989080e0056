"""The frequency response of an axis (docs/frequency-response.md): ``POST …/frequency-response`` starts the
measurement as a job (202, operation ``frequency-response``; ``progress`` events on /api/ws/events with ``stage``
and ``fraction``; cancelling the job stops the axis).  Refused before anything is written: 422 a request the drive
cannot take (frequencies beyond the SYNC rate; without a recorder, whose response then comes in synchronous
TPDOs: a plant without a current actual value, a bus too slow for the SYNC rate's frames), 409 without the axis's
armed controller (``X-Servo-Client``), 404 an unknown project or axis.  The job's result is the result dict; a limit
exceeded ends it with ``aborted`` and no points.
"""

from __future__ import annotations

from fastapi import APIRouter, status

from servostudio.api.deps import Jobs, Motion, NodeDrive, OpenBus, Projects
from servostudio.api.errors import error_responses
from servostudio.api.routes.comm_models import JobModel
from servostudio.api.routes.drives import DRIVE_ERRORS
from servostudio.api.routes.frequency_models import FrequencyStart
from servostudio.api.security import Requires
from servostudio.errors import ErrorKind
from servostudio.services.frequency.service import FrequencyService
from servostudio.services.users import Level

PATH = "/buses/{bus}/nodes/{node}/frequency-response"
router = APIRouter(tags=["frequency"])


@router.post(
    PATH,
    response_model=JobModel,
    status_code=status.HTTP_202_ACCEPTED,
    summary="Measure the plant or the closed speed loop's frequency response as a job (multi-sine by RPDO)",
    responses=error_responses(*DRIVE_ERRORS, ErrorKind.INVALID_INPUT, ErrorKind.REFUSED_FOR_SAFETY),
    dependencies=[Requires(Level.EXPERT)],  # it turns the motor: tuning and motion are the Expert's
)
def start_frequency_response(
    body: FrequencyStart, connection: OpenBus, drive: NodeDrive, jobs: Jobs, motion: Motion, projects: Projects
) -> dict:
    service = FrequencyService(projects.store)
    return service.start(jobs, motion, connection, drive, body.request()).as_dict()
