"""Backup and restore: many drives at once as background jobs, or one file of one drive as a download/upload."""

from __future__ import annotations

import shutil
import tempfile
from pathlib import Path

from fastapi import APIRouter, Body, Depends, HTTPException, status
from fastapi.responses import JSONResponse, PlainTextResponse

from servostudio.api.deps import current_user, get_connections, get_jobs
from servostudio.api.routes.comm_models import BackupRequest, JobModel, RestoreRequest
from servostudio.services.backup import (
    FileKind,
    backup_drive,
    backup_file,
    drive_file_kinds,
    restore_file,
    run_per_drive,
)
from servostudio.services.bus import BusConnection, ConnectionManager, JobRegistry

router = APIRouter(tags=["backup"], dependencies=[Depends(current_user)])


def _kinds(names: list[str] | None) -> list[FileKind] | None:
    if names is None:
        return None
    try:
        return [FileKind(name.upper()) for name in names]
    except ValueError:
        raise HTTPException(422, f"files must be among {', '.join(kind.value for kind in FileKind)}") from None


def _nodes(connection: BusConnection, nodes: list[int] | None) -> list[int]:
    chosen = nodes if nodes is not None else sorted(connection.nodes)
    if not chosen:
        raise HTTPException(422, f"no nodes given and none known on bus {connection.id}: scan the bus first")
    return chosen


@router.post(
    "/buses/{bus}/backup",
    response_model=JobModel,
    status_code=status.HTTP_202_ACCEPTED,
    summary="Back up drives in parallel into DIRECTORY/node<N>/ (progress on /api/ws/events)",
)
def start_backup(
    bus: str,
    request: BackupRequest,
    manager: ConnectionManager = Depends(get_connections),
    jobs: JobRegistry = Depends(get_jobs),
) -> dict:
    connection = manager.get(bus)
    nodes, kinds, directory = _nodes(connection, request.nodes), _kinds(request.files), Path(request.directory)

    def work(progress, cancel) -> dict:
        drives = [connection.drive(node) for node in nodes]
        results = run_per_drive(
            drives,
            lambda drive: backup_drive(
                drive, directory / f"node{drive.node}", kinds, lambda event: progress({**event, "bus": bus}), cancel
            ),
        )
        return _per_node(results)

    return jobs.start("backup", work).as_dict()


@router.post(
    "/buses/{bus}/restore",
    response_model=JobModel,
    status_code=status.HTTP_202_ACCEPTED,
    summary="Restore drives in parallel from DIRECTORY/node<N>/ (validated first, verified, stored)",
)
def start_restore(
    bus: str,
    request: RestoreRequest,
    manager: ConnectionManager = Depends(get_connections),
    jobs: JobRegistry = Depends(get_jobs),
) -> dict:
    connection = manager.get(bus)
    nodes, kinds, directory = _nodes(connection, request.nodes), _kinds(request.files), Path(request.directory)

    def work(progress, cancel) -> dict:
        def restore_one(drive):
            folder = directory / f"node{drive.node}"
            chosen = kinds or [kind for kind in drive_file_kinds(drive) if (folder / kind.value).is_file()]
            results = []
            for kind in chosen:
                if cancel.requested:  # files not started are left out of the result
                    break
                results.append(
                    restore_file(
                        drive,
                        folder / kind.value,
                        kind,
                        lambda event: progress({**event, "bus": bus}),
                        request.store,
                        cancel,
                    )
                )
            return results

        return _per_node(run_per_drive([connection.drive(node) for node in nodes], restore_one))

    return jobs.start("restore", work).as_dict()


def _per_node(results: dict[int, object]) -> dict:
    shown = {}
    for node, outcome in results.items():
        if isinstance(outcome, Exception):
            shown[str(node)] = {"error": str(outcome)}
        else:
            shown[str(node)] = [item.as_dict() for item in outcome]
    return shown


@router.get("/jobs", response_model=list[JobModel], summary="Recent jobs")
def list_jobs(jobs: JobRegistry = Depends(get_jobs)) -> list[dict]:
    return [job.as_dict() for job in jobs.list()]


@router.post(
    "/jobs/{job_id}/cancel",
    response_model=JobModel,
    summary="Cancel a running job: it stops at the next object or file boundary and ends 'cancelled'",
)
def cancel_job(job_id: str, jobs: JobRegistry = Depends(get_jobs)) -> dict:
    job = jobs.cancel(job_id)
    if job is None:
        raise HTTPException(404, f"no job {job_id!r}")
    return job.as_dict()


@router.get("/jobs/{job_id}", response_model=JobModel, summary="A job's state and result")
def get_job(job_id: str, jobs: JobRegistry = Depends(get_jobs)) -> dict:
    job = jobs.get(job_id)
    if job is None:
        raise HTTPException(404, f"no job {job_id!r}")
    return job.as_dict()


@router.get(
    "/buses/{bus}/nodes/{node}/files/{name}",
    response_class=PlainTextResponse,
    summary="Back up one file of one drive and download it (DRIVEPAR.TXT, USER_PAR.TXT, SEQUENCE.TXT)",
)
def download_file(bus: str, node: int, name: str, manager: ConnectionManager = Depends(get_connections)) -> str:
    kind = _kinds([name])[0]
    drive = manager.get(bus).drive(node)
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / kind.value
        backup_file(drive, path, kind)
        return path.read_text(encoding="latin-1")


@router.put(
    "/buses/{bus}/nodes/{node}/files/{name}",
    summary="Upload a file and restore it to the drive (validated first; 422 names the line); with "
    "job=true as a cancellable job (202, progress on /api/ws/events)",
)
def upload_file(
    bus: str,
    node: int,
    name: str,
    text: str = Body(..., media_type="text/plain"),
    store: bool = True,
    job: bool = False,
    manager: ConnectionManager = Depends(get_connections),
    jobs: JobRegistry = Depends(get_jobs),
) -> dict:
    kind = _kinds([name])[0]
    drive = manager.get(bus).drive(node)
    if job:
        return JSONResponse(_restore_upload_job(jobs, bus, drive, kind, text, store), status.HTTP_202_ACCEPTED)
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / kind.value
        path.write_text(text, encoding="latin-1")
        result = restore_file(drive, path, kind, store=store)
    shown = result.as_dict()
    shown["file"] = name
    return shown


def _restore_upload_job(jobs: JobRegistry, bus: str, drive, kind: FileKind, text: str, store: bool) -> dict:
    """The uploaded file restored by a job; its result is ``{node: [restore result]}`` like a restore job's."""
    folder = Path(tempfile.mkdtemp(prefix="servostudio-upload-"))
    path = folder / kind.value
    path.write_text(text, encoding="latin-1")

    def work(progress, cancel) -> dict:
        try:
            result = restore_file(drive, path, kind, lambda event: progress({**event, "bus": bus}), store, cancel)
        finally:
            shutil.rmtree(folder, ignore_errors=True)
        return {str(drive.node): [{**result.as_dict(), "file": kind.value}]}

    return jobs.start("restore", work).as_dict()
