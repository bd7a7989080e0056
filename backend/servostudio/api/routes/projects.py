"""Projects and axes: the project store, offline parameters, compare, motors, Device Config templates, archives, DCF;
the routes with live drives are in ``projects_live`` (included at the end), except compare and motor selection,
which take a ``drive`` switch here.

Changes take the ``revision`` the client last read; when someone else changed the project meanwhile the answer is
409 with ``error: "ConflictError"`` and nothing is written. Errors are the API's (``api.errors``).
"""

from __future__ import annotations

import dataclasses
import shutil
import tempfile
from pathlib import Path
from typing import Annotated

import anyio
from fastapi import APIRouter, File, Query, Request, Response, UploadFile
from fastapi.responses import FileResponse
from starlette.background import BackgroundTask
from starlette.concurrency import run_in_threadpool

from servostudio.api.deps import Live, Projects
from servostudio.api.errors import error_responses
from servostudio.api.limits import body_limit
from servostudio.api.routes import projects_live
from servostudio.api.routes.dictionaries import EDS_UPLOAD_BYTES
from servostudio.api.routes.drives import DRIVE_ERRORS
from servostudio.api.routes.project_models import (
    AxisChoiceModel,
    AxisCreate,
    AxisUpdate,
    CompareModel,
    CompareRowModel,
    DcfImportModel,
    KeptRevisionModel,
    MotorChoice,
    MotorModel,
    NewName,
    ParameterList,
    ParameterModel,
    ParameterReset,
    ParameterWrite,
    ProjectCreate,
    ProjectModel,
    ProjectSummary,
    ProjectUpdate,
    RevisionRestore,
    TemplateChoice,
    TemplateModel,
    ValueChangeModel,
    buses_from,
    parameter_model,
    project_model,
)
from servostudio.api.security import Requires
from servostudio.errors import ErrorKind
from servostudio.services import dictionaries
from servostudio.services.projects import ArchiveLimits, Axis, Motor, errors
from servostudio.services.projects.jsonview import (
    choice_view,
    compare_view,
    motor_view,
    summaries,
    template_view,
    value_change_view,
)
from servostudio.services.projects.templates import templates_for
from servostudio.services.users import Level

#: what the project routes may answer besides their result (the live ones meet the drives' errors too)
PROJECT_ERRORS = (ErrorKind.NOT_FOUND, ErrorKind.CONFLICT)
router = APIRouter(tags=["projects"], responses=error_responses(*PROJECT_ERRORS))


# ---- projects ---------------------------------------------------------------------------------------------------


@router.get("/projects", response_model=list[ProjectSummary], dependencies=[Requires(Level.OPERATOR)])
def list_projects(service: Projects) -> list[ProjectSummary]:
    return [ProjectSummary(**summary) for summary in summaries(service.store)]


@router.post("/projects", response_model=ProjectModel, status_code=201, dependencies=[Requires(Level.EXPERT)])
def create_project(body: ProjectCreate, service: Projects) -> ProjectModel:
    return project_model(service.store.create(body.name, body.description, buses_from(body.buses)))


#: an archive upload is compressed: it cannot usefully exceed what its members may add up to
ARCHIVE_UPLOAD_BYTES = ArchiveLimits().max_total_bytes


@router.post(
    "/projects/unarchive",
    response_model=ProjectModel,
    status_code=201,
    responses=error_responses(ErrorKind.TOO_LARGE),
    openapi_extra=body_limit(ARCHIVE_UPLOAD_BYTES),
    dependencies=[Requires(Level.EXPERT)],
)
async def unarchive(
    request: Request, service: Projects, new_name: Annotated[str | None, Query()] = None
) -> ProjectModel:
    """Body: the zip archive (``application/zip``). Its size is limited (``api.limits``) before anything is
    unpacked."""
    with tempfile.TemporaryDirectory() as scratch:
        path = Path(scratch) / "upload.zip"
        await _receive(request, path)
        snapshot = await run_in_threadpool(service.unarchive, path, new_name)
    return project_model(snapshot)


async def _receive(request: Request, path: Path) -> None:
    """Spool the request body to ``path`` (the body limit stops it early)."""
    async with await anyio.open_file(path, "wb") as stream:
        async for chunk in request.stream():
            await stream.write(chunk)


@router.get("/projects/{name}", response_model=ProjectModel, dependencies=[Requires(Level.OPERATOR)])
def get_project(name: str, service: Projects) -> ProjectModel:
    return project_model(service.store.open(name))


@router.patch("/projects/{name}", response_model=ProjectModel, dependencies=[Requires(Level.EXPERT)])
def update_project(name: str, body: ProjectUpdate, service: Projects) -> ProjectModel:
    buses = buses_from(body.buses) if body.buses is not None else None
    return project_model(service.store.update(name, body.revision, description=body.description, buses=buses))


@router.delete("/projects/{name}", status_code=204, dependencies=[Requires(Level.EXPERT)])
def delete_project(name: str, service: Projects, revision: str | None = None) -> Response:
    service.store.delete(name, revision)
    return Response(status_code=204)


@router.post("/projects/{name}/rename", response_model=ProjectModel, dependencies=[Requires(Level.EXPERT)])
def rename_project(name: str, body: NewName, service: Projects) -> ProjectModel:
    return project_model(service.store.rename(name, body.new_name, body.revision))


@router.post(
    "/projects/{name}/duplicate", response_model=ProjectModel, status_code=201, dependencies=[Requires(Level.EXPERT)]
)
def duplicate_project(name: str, body: NewName, service: Projects) -> ProjectModel:
    return project_model(service.store.duplicate(name, body.new_name))


@router.get(
    "/projects/{name}/revisions", response_model=list[KeptRevisionModel], dependencies=[Requires(Level.OPERATOR)]
)
def list_revisions(name: str, service: Projects) -> list[KeptRevisionModel]:
    """The kept revisions, newest first: the project as it was before each change that replaced many values."""
    return [KeptRevisionModel(**dataclasses.asdict(item)) for item in service.revisions(name)]


@router.post(
    "/projects/{name}/revisions/{revision}/restore", response_model=ProjectModel, dependencies=[Requires(Level.EXPERT)]
)
def restore_revision(name: str, revision: str, body: RevisionRestore, service: Projects) -> ProjectModel:
    """Make the project what it was at a kept revision; the state it replaces is kept in turn (so this undoes)."""
    return project_model(service.restore_revision(name, revision, body.revision))


@router.get("/projects/{name}/archive", response_class=FileResponse, dependencies=[Requires(Level.OPERATOR)])
def archive_project(name: str, service: Projects) -> FileResponse:
    scratch = tempfile.mkdtemp()
    path = service.archive(name, Path(scratch) / f"{name}.zip")
    return FileResponse(
        path, media_type="application/zip", filename=f"{name}.zip", background=BackgroundTask(_remove_tree, scratch)
    )


def _remove_tree(path: str) -> None:
    shutil.rmtree(path, ignore_errors=True)


# ---- axes -------------------------------------------------------------------------------------------------------


@router.post(
    "/projects/{name}/axes", response_model=ProjectModel, status_code=201, dependencies=[Requires(Level.EXPERT)]
)
def add_axis(name: str, body: AxisCreate, service: Projects) -> ProjectModel:
    axis = Axis(body.name, body.device, body.node_id, body.bus, body.description)
    return project_model(service.store.add_axis(name, axis, body.revision))


@router.patch("/projects/{name}/axes/{axis}", response_model=ProjectModel, dependencies=[Requires(Level.EXPERT)])
def edit_axis(name: str, axis: str, body: AxisUpdate, service: Projects) -> ProjectModel:
    changes = body.model_dump(exclude_none=True, exclude={"revision"})
    return project_model(service.store.edit_axis(name, axis, body.revision, **changes))


@router.delete("/projects/{name}/axes/{axis}", response_model=ProjectModel, dependencies=[Requires(Level.EXPERT)])
def remove_axis(name: str, axis: str, service: Projects, revision: str | None = None) -> ProjectModel:
    return project_model(service.store.remove_axis(name, axis, revision))


@router.get(
    "/projects/{name}/axes/{axis}/parameters", response_model=ParameterList, dependencies=[Requires(Level.OPERATOR)]
)
def list_parameters(
    name: str,
    axis: str,
    service: Projects,
    group: str | None = None,
    only_set: bool = False,
    only_differences: bool = False,
    include_unsaved: bool = False,
) -> ParameterList:
    rows, revision = service.parameters.rows(
        name, axis, group=group, only_set=only_set, only_differences=only_differences, include_unsaved=include_unsaved
    )
    return ParameterList(parameters=[parameter_model(row) for row in rows], revision=revision)


@router.get(
    "/projects/{name}/axes/{axis}/parameters/{address}",
    response_model=ParameterModel,
    dependencies=[Requires(Level.OPERATOR)],
)
def get_parameter(name: str, axis: str, address: str, service: Projects) -> ParameterModel:
    row, _revision = service.parameters.get(name, axis, address)
    return parameter_model(row)


@router.put(
    "/projects/{name}/axes/{axis}/parameters", response_model=ParameterList, dependencies=[Requires(Level.EXPERT)]
)
def set_parameters(name: str, axis: str, body: ParameterWrite, service: Projects) -> ParameterList:
    keep = f"{len(body.values)} values of axis {axis} replaced" if body.keep_revision else None
    change = service.parameters.set(name, axis, body.values, body.revision, keep)
    return ParameterList(parameters=[parameter_model(row) for row in change.rows], revision=change.revision)


@router.post(
    "/projects/{name}/axes/{axis}/parameters/reset", response_model=ParameterList, dependencies=[Requires(Level.EXPERT)]
)
def reset_parameters(name: str, axis: str, body: ParameterReset, service: Projects) -> ParameterList:
    change = service.parameters.unset(name, axis, body.addresses, body.revision)
    return ParameterList(parameters=[parameter_model(row) for row in change.rows], revision=change.revision)


@router.get(
    "/projects/{name}/axes/{axis}/compare",
    response_model=CompareModel,
    responses=error_responses(*DRIVE_ERRORS),
    dependencies=[Requires(Level.OPERATOR)],
)
def compare_axis(
    name: str,
    axis: str,
    service: Projects,
    live: Live,
    group: str | None = None,
    only_differences: bool = False,
    drive: bool = False,
    read_only: bool = False,
) -> CompareModel:
    """Project / default columns; with ``drive=true`` drive / project / default, read from the axis's live drive
    (its bus is opened on the server if needed), and a row differs when the drive's value is not the project's.
    Rows are what a user can write or restore; ``read_only=true`` adds the read-only entries apart (``read_only``)."""
    if drive:
        found = live.compare(name, axis, group=group, only_differences=only_differences, read_only=read_only)
        return CompareModel(
            columns=["drive", "project", "default"],
            revision=found.revision,
            refused=found.refused,
            rows=[CompareRowModel(**compare_view(row)) for row in found.rows],
            read_only=[CompareRowModel(**compare_view(row)) for row in found.read_only],
        )
    rows, revision = service.parameters.compare(name, axis, group=group, only_differences=only_differences)
    apart = service.parameters.read_only(name, axis, group=group) if read_only else []
    return CompareModel(
        columns=["project", "default"],
        revision=revision,
        rows=[CompareRowModel(**compare_view(row)) for row in rows],
        read_only=[CompareRowModel(**compare_view(row)) for row in apart],
    )


@router.post(
    "/projects/{name}/axes/{axis}/motor",
    response_model=AxisChoiceModel,
    responses=error_responses(*DRIVE_ERRORS),
    dependencies=[Requires(Level.EXPERT)],
)
def select_motor(name: str, axis: str, body: MotorChoice, service: Projects, live: Live) -> AxisChoiceModel:
    """Offline: the project reproduces the drive's side effects. With ``drive: true`` the motor is written to the
    axis's live drive and the values the drive derived are read back into the project."""
    if body.drive:
        choice = live.select_motor(name, axis, body.reference, body.revision)
    else:
        choice = service.select_motor(name, axis, body.reference, body.revision)
    return AxisChoiceModel(**choice_view(choice))


@router.get(
    "/projects/{name}/axes/{axis}/application",
    response_model=TemplateModel | None,
    dependencies=[Requires(Level.OPERATOR)],
)
def get_application(name: str, axis: str, service: Projects) -> TemplateModel | None:
    chosen = service.application(name, axis)
    return TemplateModel(**template_view(chosen)) if chosen is not None else None


@router.post(
    "/projects/{name}/axes/{axis}/application", response_model=AxisChoiceModel, dependencies=[Requires(Level.EXPERT)]
)
def apply_application(name: str, axis: str, body: TemplateChoice, service: Projects) -> AxisChoiceModel:
    return AxisChoiceModel(**choice_view(service.apply_template(name, axis, body.template, body.revision)))


@router.get("/projects/{name}/axes/{axis}/dcf", dependencies=[Requires(Level.OPERATOR)])
def export_dcf(name: str, axis: str, service: Projects) -> Response:
    text = service.dcf(name, axis)
    return Response(
        text.encode("latin-1"),
        media_type="text/plain; charset=latin-1",
        headers={"Content-Disposition": f'attachment; filename="{axis}.dcf"'},
    )


#: a DCF is an EDS with values: the EDS upload's limit
DCF_UPLOAD_BYTES = EDS_UPLOAD_BYTES


@router.post(
    "/projects/{name}/axes/{axis}/dcf",
    response_model=DcfImportModel,
    responses=error_responses(ErrorKind.INVALID_INPUT, ErrorKind.TOO_LARGE),
    openapi_extra=body_limit(DCF_UPLOAD_BYTES),
    dependencies=[Requires(Level.EXPERT)],
)
async def import_dcf(
    name: str,
    axis: str,
    service: Projects,
    dcf: Annotated[UploadFile, File(description="CiA 306 DCF of the axis's device")],
    revision: Annotated[str | None, Query()] = None,
    dry_run: Annotated[bool, Query(description="check and answer what would change, write nothing")] = False,
) -> DcfImportModel:
    """Set the axis's offline values to what the DCF configures (``ParameterValue``, ``$NODEID`` resolved for the
    axis), all or nothing, checked like offline edits; ``changes`` lists the values that change (old, new),
    ``skipped`` what the project cannot hold. The project as it was is kept as a revision. Errors name the file as
    uploaded."""
    text = dictionaries.upload_text(await dcf.read())
    file_name = dcf.filename or "upload.dcf"
    if dry_run:
        imported = await run_in_threadpool(service.preview_dcf, name, axis, text, file_name)
    else:
        imported = await run_in_threadpool(service.import_dcf, name, axis, text, file_name, revision)
    return DcfImportModel(
        parameters=[parameter_model(row) for row in imported.change.rows],
        changes=[ValueChangeModel(**value_change_view(change)) for change in imported.changes],
        skipped=imported.skipped,
        revision=imported.change.revision,
    )


# ---- catalog and templates --------------------------------------------------------------------------------------


@router.get("/motors", response_model=list[MotorModel], dependencies=[Requires(Level.OPERATOR)])
def list_motors(service: Projects) -> list[MotorModel]:
    return [MotorModel(**motor_view(motor)) for motor in service.motors.motors()]


@router.post("/motors", response_model=MotorModel, status_code=201, dependencies=[Requires(Level.EXPERT)])
def add_motor(body: MotorModel, service: Projects) -> MotorModel:
    """ "Add new motor": a user catalog entry (built-in references cannot be reused)."""
    objects = {}
    for key, value in body.objects.items():
        index, _sep, sub = key.partition(",")
        try:
            objects[(int(index, 16), int(sub))] = value
        except ValueError:
            raise errors.ValidationError(f'object key {key!r} must look like "0x3324,1"') from None
    motor = Motor(body.reference, body.description, body.source, dict(body.motor_data), objects)
    return MotorModel(**motor_view(service.motors.add(motor)))


@router.delete("/motors/{reference}", status_code=204, dependencies=[Requires(Level.EXPERT)])
def remove_motor(reference: str, service: Projects) -> Response:
    """Remove a user motor (built-in motors stay)."""
    service.motors.remove(reference)
    return Response(status_code=204)


@router.get("/device-templates", response_model=list[TemplateModel], dependencies=[Requires(Level.OPERATOR)])
def list_templates(device: str = "xtrapulspac") -> list[TemplateModel]:
    return [TemplateModel(**template_view(template)) for template in templates_for(device)]


router.include_router(projects_live.router)
