"""Projects and axes: the project store, offline parameters, compare, motors, Device Config templates, archives, DCF.

Changes take the ``revision`` the client last read; when someone else changed the project meanwhile the answer is
409 with ``error: "ConflictError"`` and nothing is written. Errors are ``{"detail": <message>, "error": <kind>}``.
"""

from __future__ import annotations

import shutil
import tempfile
from collections.abc import Callable, Coroutine
from pathlib import Path
from typing import Annotated, Any

from fastapi import APIRouter, Depends, Query, Request, Response
from fastapi.responses import FileResponse, JSONResponse
from fastapi.routing import APIRoute
from pydantic import BaseModel, Field
from starlette.background import BackgroundTask
from starlette.concurrency import run_in_threadpool

from servostudio.api.deps import User, current_user
from servostudio.services.projects import (
    ArchiveLimits,
    Axis,
    Bus,
    Motor,
    ParameterRow,
    ProjectService,
    Snapshot,
    errors,
)
from servostudio.services.projects.jsonview import (
    choice_view,
    compare_view,
    motor_view,
    parameter_view,
    project_view,
    summaries,
    template_view,
)
from servostudio.services.projects.templates import templates_for

_STATUS = {
    errors.ProjectNotFound: 404, errors.ProjectExists: 409, errors.ConflictError: 409, errors.InvalidName: 422,
    errors.ValidationError: 422, errors.ParameterRefused: 422, errors.ArchiveError: 422,
    errors.FileFormatError: 422,
}


class ProjectRoute(APIRoute):
    """Answers a service refusal as ``{"detail": message, "error": kind}`` with the status of its kind, the same
    shape as the communication errors (``api/routes/errors.py``), without touching the app."""

    def get_route_handler(self) -> Callable[[Request], Coroutine[Any, Any, Response]]:
        handler = super().get_route_handler()

        async def answer(request: Request) -> Response:
            try:
                return await handler(request)
            except errors.ProjectError as error:
                status = next((code for kind, code in _STATUS.items() if isinstance(error, kind)), 400)
                return JSONResponse(status_code=status, content={"detail": str(error), "error": type(error).__name__})

        return answer


router = APIRouter(tags=["projects"], route_class=ProjectRoute)


def project_service(request: Request) -> ProjectService:
    """One service per app, on the server's project store and dictionary library."""
    state = request.app.state
    if getattr(state, "project_service", None) is None:
        state.project_service = ProjectService(state.settings.projects_dir, state.eds_library)
    return state.project_service


Service = Annotated[ProjectService, Depends(project_service)]
Caller = Annotated[User, Depends(current_user)]


# ---- models -----------------------------------------------------------------------------------------------------

class BusModel(BaseModel):
    name: str = Field(examples=["sim"])
    interface: str = Field(examples=["sim", "socketcan:can0"])
    bitrate: int | None = Field(default=None, examples=[1000000])


class AxisModel(BaseModel):
    name: str = Field(examples=["X"])
    device: str = Field(examples=["xtrapulspac"])
    node_id: int = Field(examples=[1])
    bus: str = Field(examples=["sim"])
    description: str = ""
    motor: str = ""
    application: str = ""


class ProjectModel(BaseModel):
    name: str
    description: str
    buses: list[BusModel]
    axes: list[AxisModel]
    revision: str = Field(description="pass back with the next change (optimistic concurrency)")


class ProjectSummary(BaseModel):
    name: str
    description: str
    axis_count: int
    revision: str
    error: str | None = Field(description="why the project cannot be opened; null when it is fine")


class ProjectCreate(BaseModel):
    name: str
    description: str = ""
    buses: list[BusModel] = []


class ProjectUpdate(BaseModel):
    description: str | None = None
    buses: list[BusModel] | None = None
    revision: str | None = None


class NewName(BaseModel):
    new_name: str
    revision: str | None = None


class AxisCreate(AxisModel):
    revision: str | None = None


class AxisUpdate(BaseModel):
    name: str | None = None
    device: str | None = None
    node_id: int | None = None
    bus: str | None = None
    description: str | None = None
    revision: str | None = None


Scalar = int | float | str | None


class ParameterModel(BaseModel):
    index: int
    subindex: int
    name: str = Field(description="e.g. '0x60F9,2 Speed loop gains.KPv'")
    group: str
    data_type: str
    access: str
    save_type: str
    unit: str
    value: Scalar = Field(description="project value: set in the axis files, else the default (raw units)")
    default: Scalar
    differs_from_default: bool
    file: str | None = Field(description="DRIVEPAR.TXT / USER_PAR.TXT when the project sets it, else null")
    editable: bool
    not_editable_reason: str | None


class ParameterList(BaseModel):
    parameters: list[ParameterModel]
    revision: str


class ParameterWrite(BaseModel):
    values: dict[str, int | float | str] = Field(examples=[{"0x6060": -3, "0x60F9,2": 1200}])
    revision: str | None = None


class ParameterReset(BaseModel):
    addresses: list[str]
    revision: str | None = None


class CompareRowModel(BaseModel):
    index: int
    subindex: int
    name: str
    group: str
    unit: str
    values: dict[str, Scalar] = Field(description="column -> value; columns drive (later) / project / default")
    differs: bool


class CompareModel(BaseModel):
    columns: list[str]
    rows: list[CompareRowModel]
    revision: str


class AxisChoiceModel(BaseModel):
    changed: list[ParameterModel]
    notes: list[str] = Field(description="consequences not reproduced offline, or reproduced without some inputs")
    project: ProjectModel


class MotorChoice(BaseModel):
    reference: str
    revision: str | None = None


class TemplateChoice(BaseModel):
    template: str = Field(examples=["analog-speed", "positioner", "stepper-emulation", "expert"])
    revision: str | None = None


class SettingModel(BaseModel):
    index: int
    subindex: int
    value: int
    why: str


class TemplateModel(BaseModel):
    key: str
    title: str
    description: str
    settings: list[SettingModel]
    groups: list[str] | None = Field(description="parameter groups the UI shows; null = all (Expert mode)")


class MotorModel(BaseModel):
    reference: str
    description: str = ""
    source: str = ""
    motor_data: dict[str, int | str] = Field(description="0x6410 sub-entries by name, raw object units")
    objects: dict[str, int | float | str] = Field(default={}, description='other objects, keys like "0x3324,1"')
    builtin: bool = False


# ---- conversions (the dict views are shared with the CLI) ---------------------------------------------------------

def _project(snapshot: Snapshot) -> ProjectModel:
    return ProjectModel(**project_view(snapshot))


def _parameter(row: ParameterRow) -> ParameterModel:
    return ParameterModel(**parameter_view(row))


def _buses(models: list[BusModel]) -> tuple[Bus, ...]:
    return tuple(Bus(b.name, b.interface, b.bitrate) for b in models)


# ---- projects ---------------------------------------------------------------------------------------------------

@router.get("/projects", response_model=list[ProjectSummary])
def list_projects(service: Service, _: Caller) -> list[ProjectSummary]:
    return [ProjectSummary(**summary) for summary in summaries(service.store)]


@router.post("/projects", response_model=ProjectModel, status_code=201)
def create_project(body: ProjectCreate, service: Service, _: Caller) -> ProjectModel:
    return _project(service.store.create(body.name, body.description, _buses(body.buses)))


@router.post("/projects/unarchive", response_model=ProjectModel, status_code=201)
async def unarchive(request: Request, service: Service, _: Caller,
                    new_name: Annotated[str | None, Query()] = None) -> Response:
    """Body: the zip archive (``application/zip``). Its size is limited before anything is unpacked."""
    limits = ArchiveLimits()
    with tempfile.TemporaryDirectory() as scratch:
        path = Path(scratch) / "upload.zip"
        size = 0
        with open(path, "wb") as stream:
            async for chunk in request.stream():
                size += len(chunk)
                if size > limits.max_total_bytes:
                    return JSONResponse(status_code=413, content={
                        "detail": f"archive larger than {limits.max_total_bytes} bytes", "error": "ArchiveError"})
                stream.write(chunk)
        snapshot = await run_in_threadpool(service.unarchive, path, new_name, limits)
    return JSONResponse(status_code=201, content=_project(snapshot).model_dump())


@router.get("/projects/{name}", response_model=ProjectModel)
def get_project(name: str, service: Service, _: Caller) -> ProjectModel:
    return _project(service.store.open(name))


@router.patch("/projects/{name}", response_model=ProjectModel)
def update_project(name: str, body: ProjectUpdate, service: Service, _: Caller) -> ProjectModel:
    buses = _buses(body.buses) if body.buses is not None else None
    return _project(service.store.update(name, body.revision, description=body.description, buses=buses))


@router.delete("/projects/{name}", status_code=204)
def delete_project(name: str, service: Service, _: Caller, revision: str | None = None) -> Response:
    service.store.delete(name, revision)
    return Response(status_code=204)


@router.post("/projects/{name}/rename", response_model=ProjectModel)
def rename_project(name: str, body: NewName, service: Service, _: Caller) -> ProjectModel:
    return _project(service.store.rename(name, body.new_name, body.revision))


@router.post("/projects/{name}/duplicate", response_model=ProjectModel, status_code=201)
def duplicate_project(name: str, body: NewName, service: Service, _: Caller) -> ProjectModel:
    return _project(service.store.duplicate(name, body.new_name))


@router.get("/projects/{name}/archive", response_class=FileResponse)
def archive_project(name: str, service: Service, _: Caller) -> FileResponse:
    scratch = tempfile.mkdtemp()
    path = service.archive(name, Path(scratch) / f"{name}.zip")
    return FileResponse(path, media_type="application/zip", filename=f"{name}.zip",
                        background=BackgroundTask(_remove_tree, scratch))


def _remove_tree(path: str) -> None:
    shutil.rmtree(path, ignore_errors=True)


# ---- axes -------------------------------------------------------------------------------------------------------

@router.post("/projects/{name}/axes", response_model=ProjectModel, status_code=201)
def add_axis(name: str, body: AxisCreate, service: Service, _: Caller) -> ProjectModel:
    axis = Axis(body.name, body.device, body.node_id, body.bus, body.description)
    return _project(service.store.add_axis(name, axis, body.revision))


@router.patch("/projects/{name}/axes/{axis}", response_model=ProjectModel)
def edit_axis(name: str, axis: str, body: AxisUpdate, service: Service, _: Caller) -> ProjectModel:
    changes = body.model_dump(exclude_none=True, exclude={"revision"})
    return _project(service.store.edit_axis(name, axis, body.revision, **changes))


@router.delete("/projects/{name}/axes/{axis}", response_model=ProjectModel)
def remove_axis(name: str, axis: str, service: Service, _: Caller, revision: str | None = None) -> ProjectModel:
    return _project(service.store.remove_axis(name, axis, revision))


@router.get("/projects/{name}/axes/{axis}/parameters", response_model=ParameterList)
def list_parameters(name: str, axis: str, service: Service, _: Caller, group: str | None = None,
                    only_set: bool = False, only_differences: bool = False,
                    include_unsaved: bool = False) -> ParameterList:
    rows, revision = service.parameters.rows(name, axis, group=group, only_set=only_set,
                                             only_differences=only_differences, include_unsaved=include_unsaved)
    return ParameterList(parameters=[_parameter(row) for row in rows], revision=revision)


@router.get("/projects/{name}/axes/{axis}/parameters/{address}", response_model=ParameterModel)
def get_parameter(name: str, axis: str, address: str, service: Service, _: Caller) -> ParameterModel:
    row, _revision = service.parameters.get(name, axis, address)
    return _parameter(row)


@router.put("/projects/{name}/axes/{axis}/parameters", response_model=ParameterList)
def set_parameters(name: str, axis: str, body: ParameterWrite, service: Service, _: Caller) -> ParameterList:
    change = service.parameters.set(name, axis, body.values, body.revision)
    return ParameterList(parameters=[_parameter(row) for row in change.rows], revision=change.revision)


@router.post("/projects/{name}/axes/{axis}/parameters/reset", response_model=ParameterList)
def reset_parameters(name: str, axis: str, body: ParameterReset, service: Service, _: Caller) -> ParameterList:
    change = service.parameters.unset(name, axis, body.addresses, body.revision)
    return ParameterList(parameters=[_parameter(row) for row in change.rows], revision=change.revision)


@router.get("/projects/{name}/axes/{axis}/compare", response_model=CompareModel)
def compare_axis(name: str, axis: str, service: Service, _: Caller, group: str | None = None,
                 only_differences: bool = False) -> CompareModel:
    rows, revision = service.parameters.compare(name, axis, group=group, only_differences=only_differences)
    return CompareModel(columns=["project", "default"], revision=revision,
                        rows=[CompareRowModel(**compare_view(row)) for row in rows])


@router.post("/projects/{name}/axes/{axis}/motor", response_model=AxisChoiceModel)
def select_motor(name: str, axis: str, body: MotorChoice, service: Service, _: Caller) -> AxisChoiceModel:
    return AxisChoiceModel(**choice_view(service.select_motor(name, axis, body.reference, body.revision)))


@router.get("/projects/{name}/axes/{axis}/application", response_model=TemplateModel | None)
def get_application(name: str, axis: str, service: Service, _: Caller) -> TemplateModel | None:
    chosen = service.application(name, axis)
    return TemplateModel(**template_view(chosen)) if chosen is not None else None


@router.post("/projects/{name}/axes/{axis}/application", response_model=AxisChoiceModel)
def apply_application(name: str, axis: str, body: TemplateChoice, service: Service, _: Caller) -> AxisChoiceModel:
    return AxisChoiceModel(**choice_view(service.apply_template(name, axis, body.template, body.revision)))


@router.get("/projects/{name}/axes/{axis}/dcf")
def export_dcf(name: str, axis: str, service: Service, _: Caller) -> Response:
    text = service.dcf(name, axis)
    return Response(text.encode("latin-1"), media_type="text/plain; charset=latin-1",
                    headers={"Content-Disposition": f'attachment; filename="{axis}.dcf"'})


# ---- catalog and templates --------------------------------------------------------------------------------------

@router.get("/motors", response_model=list[MotorModel])
def list_motors(service: Service, _: Caller) -> list[MotorModel]:
    return [MotorModel(**motor_view(motor)) for motor in service.motors.motors()]


@router.post("/motors", response_model=MotorModel, status_code=201)
def add_motor(body: MotorModel, service: Service, _: Caller) -> MotorModel:
    """"Add new motor": a user catalog entry (built-in references cannot be reused)."""
    objects = {}
    for key, value in body.objects.items():
        index, _sep, sub = key.partition(",")
        try:
            objects[(int(index, 16), int(sub))] = value
        except ValueError:
            raise errors.ValidationError(f"object key {key!r} must look like \"0x3324,1\"") from None
    motor = Motor(body.reference, body.description, body.source, dict(body.motor_data), objects)
    return MotorModel(**motor_view(service.motors.add(motor)))


@router.delete("/motors/{reference}", status_code=204)
def remove_motor(reference: str, service: Service, _: Caller) -> Response:
    """Remove a user motor (built-in motors stay)."""
    service.motors.remove(reference)
    return Response(status_code=204)


@router.get("/device-templates", response_model=list[TemplateModel])
def list_templates(_: Caller, device: str = "xtrapulspac") -> list[TemplateModel]:
    return [TemplateModel(**template_view(template)) for template in templates_for(device)]
