"""Projects with live drives: take drive values into the project, write project values to the drive, commission
(a background job: check, download or upload, progress on ``/api/ws/events``), scan a bus into a project.

Compare with the drive (``GET …/compare?drive=true``) and live motor selection (``POST …/motor`` with ``drive``)
extend the offline routes in ``projects.py``. The buses are the server's (``ConnectionManager``): a project bus is
opened on first use and shared with every other client.
"""

from __future__ import annotations

from typing import Literal

from fastapi import APIRouter, status
from pydantic import BaseModel, Field

from servostudio.api.deps import Jobs, Live
from servostudio.api.errors import error_responses
from servostudio.api.routes.comm_models import JobModel, NodeIdentity
from servostudio.api.routes.drives import DRIVE_ERRORS
from servostudio.api.routes.project_models import ParameterList, ProjectModel, parameter_model, project_model
from servostudio.api.security import Requires
from servostudio.services.users import Level

router = APIRouter(tags=["projects"], responses=error_responses(*DRIVE_ERRORS))


class TakeRequest(BaseModel):
    addresses: list[str] | None = Field(
        default=None,
        description="objects to take; null = every object whose drive value differs from the project's",
        examples=[["0x6060", "0x60F9,2"]],
    )
    revision: str | None = None


class WriteRequest(BaseModel):
    addresses: list[str] | None = Field(
        default=None, description="objects to write; null = every object whose drive value differs from the project's"
    )
    store: bool = Field(default=False, description="save the drive's parameters to flash afterwards")


class DriveWriteModel(BaseModel):
    address: str
    name: str
    value: int | float | str | None = Field(description="the project value written")
    status: str = Field(description="written | failed | not written")
    error: str | None
    drive: int | float | str | None = Field(description="the drive's value read back afterwards")


class DriveWriteReportModel(BaseModel):
    axis: str
    ok: bool
    stored: bool
    objects: list[DriveWriteModel]


class CommissionRequest(BaseModel):
    direction: Literal["check", "download", "upload"] = Field(
        default="check",
        description="check: identify every axis's drive; download: project → drives (validated, "
        "written, verified, stored); upload: drives → project files",
    )
    axes: list[str] | None = Field(default=None, description="axes to commission; null = all")
    revision: str | None = None


class ScanRequest(BaseModel):
    bus: str = Field(
        examples=["sim", "socketcand:127.0.0.1:29536"],
        description="a bus of the project (name) or a bus spec; a new spec is added to the project as a bus",
    )
    bus_name: str | None = Field(default=None, description="name of the new bus (default: derived from the spec)")
    create: bool = Field(default=False, description="create the project if it does not exist")
    revision: str | None = None


class ScannedNodeModel(BaseModel):
    node_id: int
    device: str | None
    status: str = Field(description="added | present | conflict | unknown_device | refused")
    axis: str | None = Field(description="the axis added or already there")
    reason: str | None
    identity: NodeIdentity


class ScanResultModel(BaseModel):
    bus: str
    bus_added: bool
    nodes: list[ScannedNodeModel]
    project: ProjectModel


@router.post(
    "/projects/{name}/axes/{axis}/take-from-drive", response_model=ParameterList, dependencies=[Requires(Level.EXPERT)]
)
def take_from_drive(name: str, axis: str, body: TakeRequest, live: Live) -> ParameterList:
    """Store the drive's values in the project (checked like offline edits; all or nothing)."""
    change = live.take(name, axis, body.addresses, body.revision)
    return ParameterList(parameters=[parameter_model(row) for row in change.rows], revision=change.revision)


@router.post(
    "/projects/{name}/axes/{axis}/write-to-drive",
    response_model=DriveWriteReportModel,
    dependencies=[Requires(Level.EXPERT)],
)
def write_to_drive(name: str, axis: str, body: WriteRequest, live: Live) -> DriveWriteReportModel:
    """Write the project's values to the drive; every value is checked like an online write before the first is
    sent, so one bad value writes nothing (422)."""
    report = live.write(name, axis, body.addresses, body.store)
    return DriveWriteReportModel.model_validate(report.as_dict())


@router.post(
    "/projects/{name}/commission",
    response_model=JobModel,
    status_code=status.HTTP_202_ACCEPTED,
    dependencies=[Requires(Level.MAINTENANCE)],
)
def start_commission(name: str, body: CommissionRequest, live: Live, jobs: Jobs) -> dict:
    """Runs as a job: follow ``progress`` and ``job`` events on ``/api/ws/events`` or poll ``GET /api/jobs/{id}``;
    the result is the report per axis (status ok / bus_down / no_answer / wrong_device, files restored or read)."""
    return live.start_commission(jobs, name, body.direction, body.axes, body.revision).as_dict()


@router.post("/projects/{name}/scan", response_model=ScanResultModel, dependencies=[Requires(Level.EXPERT)])
def scan_into_project(name: str, body: ScanRequest, live: Live) -> ScanResultModel:
    """Scan a bus and add an axis for every identified node not yet in the project (one project change)."""
    report = live.scan(name, body.bus, body.bus_name, body.revision, body.create)
    return ScanResultModel(
        bus=report.bus.name,
        bus_added=report.bus_added,
        nodes=[ScannedNodeModel.model_validate(node.as_dict()) for node in report.nodes],
        project=project_model(report.snapshot),
    )
