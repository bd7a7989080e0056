"""Backup and restore: many drives at once as background jobs, or one file of one drive as a download/upload."""

from __future__ import annotations

import json
from typing import Annotated

from fastapi import APIRouter, Body, Response, status
from fastapi.responses import JSONResponse, PlainTextResponse
from pydantic import BaseModel, Field

from servostudio.api.deps import Jobs, NodeDrive, OpenBus, Server
from servostudio.api.errors import error_responses
from servostudio.api.limits import MIB, body_limit
from servostudio.api.routes.comm_models import BackupRequest, JobModel, RestoreRequest
from servostudio.api.routes.drives import DRIVE_ERRORS
from servostudio.api.security import Requires
from servostudio.errors import ErrorKind
from servostudio.services import backup, transfers
from servostudio.services.users import Level

router = APIRouter(tags=["backup"])
#: A drive file as uploaded: its bytes (8-bit text, read as Latin-1, so any byte is accepted); an empty body is an
#: empty file, which is valid (it sets nothing).
DRIVE_FILE_BYTES = 1 * MIB  # a full SEQUENCE.TXT (128 sequences) is about 100 kB
BACKUP_RESULT_HEADER = "X-Backup-Result"
BACKUP_RESULT = "the backup's result as JSON: {node, file, kind, objects, skipped: [{object, reason}], seconds}"
FileBytes = Annotated[bytes, Body(media_type="text/plain", description="the drive file (8-bit text, Latin-1)")]


@router.post(
    "/buses/{bus}/backup",
    response_model=JobModel,
    status_code=status.HTTP_202_ACCEPTED,
    summary="Back up drives in parallel into DIRECTORY/node<N>/ (progress on /api/ws/events)",
    responses=error_responses(ErrorKind.NOT_FOUND),
    dependencies=[Requires(Level.MAINTENANCE)],
)
def start_backup(request: BackupRequest, connection: OpenBus, jobs: Jobs, server: Server) -> dict:
    roots = server.settings.transfer_roots
    return transfers.start_backup(jobs, connection, roots, request.directory, request.nodes, request.files).as_dict()


@router.post(
    "/buses/{bus}/restore",
    response_model=JobModel,
    status_code=status.HTTP_202_ACCEPTED,
    summary="Restore drives in parallel from DIRECTORY/node<N>/ (validated first, verified, stored)",
    responses=error_responses(ErrorKind.NOT_FOUND),
    dependencies=[Requires(Level.MAINTENANCE)],
)
def start_restore(request: RestoreRequest, connection: OpenBus, jobs: Jobs, server: Server) -> dict:
    roots = server.settings.transfer_roots
    job = transfers.start_restore(
        jobs, connection, roots, request.directory, request.nodes, request.files, request.store
    )
    return job.as_dict()


@router.get("/jobs", response_model=list[JobModel], summary="Recent jobs", dependencies=[Requires(Level.OPERATOR)])
def list_jobs(jobs: Jobs) -> list[dict]:
    return [job.as_dict() for job in jobs.list()]


@router.post(
    "/jobs/{job_id}/cancel",
    response_model=JobModel,
    summary="Cancel a running job: it stops at the next object or file boundary and ends 'cancelled'",
    responses=error_responses(ErrorKind.NOT_FOUND),
    dependencies=[Requires(Level.MAINTENANCE)],
)
def cancel_job(job_id: str, jobs: Jobs) -> dict:
    return jobs.cancel(job_id).as_dict()


@router.get(
    "/jobs/{job_id}",
    response_model=JobModel,
    summary="A job's state and result",
    responses=error_responses(ErrorKind.NOT_FOUND),
    dependencies=[Requires(Level.OPERATOR)],
)
def get_job(job_id: str, jobs: Jobs) -> dict:
    return jobs.get(job_id).as_dict()


@router.get(
    "/buses/{bus}/nodes/{node}/files/{name}",
    response_class=PlainTextResponse,
    summary="Back up one file of one drive and download it (DRIVEPAR.TXT, USER_PAR.TXT, SEQUENCE.TXT)",
    responses={
        **error_responses(*DRIVE_ERRORS),
        200: {"headers": {BACKUP_RESULT_HEADER: {"description": BACKUP_RESULT, "schema": {"type": "string"}}}},
    },
    dependencies=[Requires(Level.MAINTENANCE)],
)
def download_file(name: str, drive: NodeDrive) -> PlainTextResponse:
    text, result = transfers.download(drive, transfers.file_kind(name))
    return PlainTextResponse(text, headers={BACKUP_RESULT_HEADER: json.dumps(result, separators=(",", ":"))})


@router.put(
    "/buses/{bus}/nodes/{node}/files/{name}",
    summary="Upload a file and restore it to the drive (validated first; 422 names the line); with "
    "job=true as a cancellable job (202, progress on /api/ws/events)",
    responses={
        **error_responses(*DRIVE_ERRORS, ErrorKind.TOO_LARGE),
        status.HTTP_202_ACCEPTED: {"model": JobModel, "description": "with job=true: the restore job, started"},
    },
    openapi_extra=body_limit(DRIVE_FILE_BYTES),
    dependencies=[Requires(Level.MAINTENANCE)],
)
def upload_file(
    name: str,
    connection: OpenBus,
    drive: NodeDrive,
    jobs: Jobs,
    data: FileBytes = b"",
    store: bool = True,
    job: bool = False,
) -> Response:
    kind = transfers.file_kind(name)
    if job:
        started = transfers.start_upload(jobs, connection, drive, kind, data, store)
        return JSONResponse(started.as_dict(), status.HTTP_202_ACCEPTED)
    return JSONResponse({**transfers.upload(drive, kind, data, store).as_dict(), "file": name})


class StoreModel(BaseModel):
    node: int
    stored: str = Field(description="the profile's procedure that ran", examples=["save"])
    wrote: str = Field(
        description="what it wrote, in the dictionary's words",
        examples=["PNU 729 Save parameters in EEPROM = 1", "0x1010,1 Store parameters.Save all parameters = 'save'"],
    )
    seconds: float


@router.post(
    "/buses/{bus}/nodes/{node}/store",
    response_model=StoreModel,
    summary="Store the drive's parameters in its non-volatile memory (the profile's save: 0x1010,1 = 'save', a "
    "TTA-PRO's PNU 729 = 1); refused while enabled on a drive that saves only disabled",
    responses=error_responses(*DRIVE_ERRORS),
    dependencies=[Requires(Level.MAINTENANCE)],
)
def store_parameters(drive: NodeDrive) -> dict:
    return backup.store_parameters(drive)
