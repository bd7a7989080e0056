"""The oscilloscope: live captures of a node's recorder, and captures saved in a project under their axis.

A capture runs as a job (``POST …/scope/captures`` → 202 with the job; its ``progress`` events on /api/ws/events
name the recorder's stage, the upload's bytes and each capture made); a definition the drive cannot capture is
refused with 422 and the reason before anything is armed. ``…/scope/stop`` ends the job and the recorder (an
Operator's way out; ``/api/jobs/{id}/cancel`` does the same for Maintenance and above).
"""

from __future__ import annotations

import asyncio
import contextlib
import json
from collections.abc import Callable

from fastapi import APIRouter, Response, WebSocket, WebSocketDisconnect, status

from servostudio.api.auth import identify
from servostudio.api.deps import Access, Jobs, NodeDrive, OpenBus, Projects, ScopeCaptures
from servostudio.api.downloads import file_download
from servostudio.api.errors import error_body, error_responses
from servostudio.api.routes.comm_models import JobModel
from servostudio.api.routes.drives import DRIVE_ERRORS
from servostudio.api.routes.scope_models import (
    CaptureModel,
    CaptureRequest,
    PlanModel,
    RecorderStatus,
    RollModel,
    RollRequest,
    SavedCaptureModel,
    SaveRequest,
    ScopeInfo,
    capture_model,
    plan_model,
    saved_model,
)
from servostudio.api.security import Requires, require_message
from servostudio.errors import ErrorKind, ServoStudioError
from servostudio.services.scope import Capture, CaptureStore, capture_csv, capture_html, check
from servostudio.services.scope.roll import RollFeed
from servostudio.services.scope.service import UnknownCapture
from servostudio.services.users import AccessControl, Level

LIVE = "/buses/{bus}/nodes/{node}/scope"
SAVED = "/projects/{project}/axes/{axis}/captures"
SAVED_ERRORS = (ErrorKind.NOT_FOUND, ErrorKind.CONFLICT)
#: the roll socket's client messages and the level each needs (checked per message, with the caller as it is then)
ROLL_MESSAGES: dict[str, Level] = {"stop": Level.OPERATOR}
#: how often the roll socket sends what the roll delivered (the display latency's share of the server)
ROLL_SEND_SECONDS = 0.01
router = APIRouter(tags=["scope"])


# ---- live -------------------------------------------------------------------------------------------------------


@router.get(
    LIVE,
    response_model=ScopeInfo,
    summary="The node's recorder: channels, buffer, base period, status, and the presets it can run",
    responses=error_responses(*DRIVE_ERRORS),
    dependencies=[Requires(Level.OPERATOR)],
)
def get_scope(drive: NodeDrive, scope: ScopeCaptures) -> dict:
    return scope.describe(drive)


@router.post(
    f"{LIVE}/check",
    response_model=PlanModel,
    summary="Check a capture definition without arming anything: the plan, with the rate and bus load of a TPDO "
    "or polled capture (422 says why not)",
    responses=error_responses(*DRIVE_ERRORS),
    dependencies=[Requires(Level.OPERATOR)],
)
def check_capture(request: CaptureRequest, connection: OpenBus, drive: NodeDrive) -> PlanModel:
    return plan_model(check(drive, request.definition(), connection.drive, connection.spec.bitrate))


@router.post(
    f"{LIVE}/captures",
    response_model=JobModel,
    status_code=status.HTTP_202_ACCEPTED,
    summary="Arm the recorder and capture as a job (single: one recording; normal, auto: until stopped)",
    responses=error_responses(*DRIVE_ERRORS),
    dependencies=[Requires(Level.OPERATOR)],
)
def start_capture(
    request: CaptureRequest, connection: OpenBus, drive: NodeDrive, jobs: Jobs, scope: ScopeCaptures
) -> dict:
    return scope.start(jobs, connection, drive, request.definition()).as_dict()


@router.post(
    f"{LIVE}/roll",
    response_model=RollModel,
    status_code=status.HTTP_202_ACCEPTED,
    summary="Live roll mode: stream up to 4 channels per axis through TPDOs at the server's SYNC (the bus budget is "
    "checked first: 422 when over-subscribed); the samples on the WebSocket the answer names",
    responses=error_responses(*DRIVE_ERRORS),
    dependencies=[Requires(Level.OPERATOR)],
)
def start_roll(request: RollRequest, connection: OpenBus, drive: NodeDrive, jobs: Jobs, scope: ScopeCaptures) -> dict:
    job, plan = scope.start_roll(jobs, connection, drive, request.definition(), request.seconds, request.record)
    return {"job": job.as_dict(), "plan": plan_model(plan), "socket": f"/api/ws/scope/{job.id}"}


@router.websocket("/ws/scope/{roll}", dependencies=[Requires(Level.OPERATOR)])
async def roll_socket(socket: WebSocket, roll: str, scope: ScopeCaptures, jobs: Jobs, control: Access) -> None:
    """A roll's events as JSON: ``samples`` (``seq`` of the first, ``count``, ``values`` per channel in physical
    units, ``synced_at`` of the first and last sample's SYNC, Unix s), ``gap`` (``from``, ``to``, ``reason``) and
    ``end`` (the summary). The client may send ``{"type": "stop"}`` (Operator) to end the roll. A roll without
    ``seconds`` ends when its last socket closes (nobody would stop it otherwise: it would hold the axes and the
    bus's SYNC for good)."""
    await socket.accept()
    try:
        feed = scope.feed(roll)
    except ServoStudioError as error:
        await socket.close(code=4404, reason=str(error))
        return
    receiver = asyncio.create_task(_roll_messages(socket, control, lambda: jobs.cancel(roll)))
    feed.join(+1)
    try:
        await _send_roll(socket, feed, receiver)
    except (WebSocketDisconnect, RuntimeError):  # RuntimeError: sending after the client closed
        pass
    finally:
        receiver.cancel()
        if feed.join(-1):
            jobs.cancel(roll)


async def _send_roll(socket: WebSocket, feed: RollFeed, receiver: asyncio.Task[None]) -> None:
    cursor = 0
    while not receiver.done():
        events, cursor = feed.since(cursor)
        for _, text in events:
            await socket.send_text(text)  # encoded once by the feed for every socket following the roll
        if any(event["type"] == "end" for event, _ in events):
            await socket.close()
            return
        await asyncio.sleep(ROLL_SEND_SECONDS)


async def _roll_messages(socket: WebSocket, control: AccessControl, stop: Callable[[], object]) -> None:
    """Client messages until it disconnects: a stop of a caller at its level ends the roll; a refused one is
    answered with the error (as the terminal does); anything else is ignored."""
    with contextlib.suppress(WebSocketDisconnect):
        while True:
            text = await socket.receive_text()
            with contextlib.suppress(ValueError):
                message = json.loads(text)
                kind = str(message.get("type")) if isinstance(message, dict) else ""
                try:
                    require_message(identify(socket, control), ROLL_MESSAGES, kind, "scope roll")
                except ServoStudioError as error:
                    await socket.send_json({"type": "error", **error_body(error)})
                    continue
                if kind == "stop":
                    stop()


@router.get(
    f"{LIVE}/status",
    response_model=RecorderStatus,
    summary="The recorder's status and the node's running capture job",
    responses=error_responses(*DRIVE_ERRORS),
    dependencies=[Requires(Level.OPERATOR)],
)
def get_status(bus: str, drive: NodeDrive, scope: ScopeCaptures) -> dict:
    return scope.status(bus, drive)


@router.post(
    f"{LIVE}/force",
    response_model=RecorderStatus,
    summary="Force the trigger: the next sample is the trigger sample (while filling or waiting)",
    responses=error_responses(*DRIVE_ERRORS),
    dependencies=[Requires(Level.OPERATOR)],
)
def force_trigger(bus: str, drive: NodeDrive, scope: ScopeCaptures) -> dict:
    scope.force(drive, bus)
    return scope.status(bus, drive)


@router.post(
    f"{LIVE}/stop",
    response_model=RecorderStatus,
    summary="Stop the node's capture job and the recorder (the last complete recording stays readable)",
    responses=error_responses(*DRIVE_ERRORS),
    dependencies=[Requires(Level.OPERATOR)],
)
def stop_capture(bus: str, drive: NodeDrive, scope: ScopeCaptures) -> dict:
    scope.stop(bus, drive)
    return scope.status(bus, drive)


@router.get(
    LIVE + "/captures/{capture_id}",
    response_model=CaptureModel,
    summary="A capture the server keeps (its id comes in the job's result and progress events)",
    responses=error_responses(ErrorKind.NOT_FOUND),
    dependencies=[Requires(Level.OPERATOR)],
)
def get_capture(bus: str, node: int, capture_id: str, scope: ScopeCaptures) -> CaptureModel:
    return capture_model(_live(scope, bus, node, capture_id), capture_id)


@router.get(
    LIVE + "/captures/{capture_id}/csv",
    response_class=Response,
    summary="A capture as CSV (docs/scope.md, capture file format)",
    responses={**error_responses(ErrorKind.NOT_FOUND), 200: {"content": {"text/csv": {}}}},
    dependencies=[Requires(Level.OPERATOR)],
)
def get_capture_csv(bus: str, node: int, capture_id: str, scope: ScopeCaptures) -> Response:
    made = _live(scope, bus, node, capture_id)
    return file_download(capture_csv(made), "text/csv", f"{_default_name(made)}.csv")


@router.get(
    LIVE + "/captures/{capture_id}/html",
    response_class=Response,
    summary="A capture as a standalone interactive HTML file (opens offline)",
    responses={**error_responses(ErrorKind.NOT_FOUND), 200: {"content": {"text/html": {}}}},
    dependencies=[Requires(Level.OPERATOR)],
)
def get_capture_html(bus: str, node: int, capture_id: str, scope: ScopeCaptures) -> Response:
    made = _live(scope, bus, node, capture_id)
    return file_download(capture_html(made), "text/html", f"{_default_name(made)}.html")


def _live(scope: ScopeCaptures, bus: str, node: int, capture_id: str) -> Capture:
    """The capture of that id, if it came from the node the path names."""
    made = scope.get(capture_id)
    if (made.drive.bus, made.drive.node) != (bus, node):
        raise UnknownCapture(f"no capture {capture_id!r} of bus {bus!r} node {node}")
    return made


# ---- saved in a project -----------------------------------------------------------------------------------------


@router.get(
    SAVED,
    response_model=list[SavedCaptureModel],
    summary="The captures saved under the axis (a damaged one names its file and line in `error`)",
    responses=error_responses(*SAVED_ERRORS),
    dependencies=[Requires(Level.OPERATOR)],
)
def list_saved(project: str, axis: str, projects: Projects) -> list[SavedCaptureModel]:
    return [saved_model(saved) for saved in CaptureStore(projects.store).list(project, axis)]


@router.post(
    SAVED,
    response_model=CaptureModel,
    status_code=status.HTTP_201_CREATED,
    summary="Save a live capture under the axis as CSV + JSON sidecar",
    responses=error_responses(*SAVED_ERRORS),
    dependencies=[Requires(Level.OPERATOR)],
)
def save_capture(project: str, axis: str, body: SaveRequest, projects: Projects, scope: ScopeCaptures) -> CaptureModel:
    return capture_model(CaptureStore(projects.store).save(project, axis, scope.get(body.capture), body.name))


@router.get(
    SAVED + "/{name}",
    response_model=CaptureModel,
    summary="Re-open a saved capture (422 names the file and line of a damaged one)",
    responses=error_responses(*SAVED_ERRORS),
    dependencies=[Requires(Level.OPERATOR)],
)
def open_saved(project: str, axis: str, name: str, projects: Projects) -> CaptureModel:
    return capture_model(CaptureStore(projects.store).open(project, axis, name))


@router.get(
    SAVED + "/{name}/csv",
    response_class=Response,
    summary="A saved capture's CSV",
    responses={**error_responses(*SAVED_ERRORS), 200: {"content": {"text/csv": {}}}},
    dependencies=[Requires(Level.OPERATOR)],
)
def saved_csv(project: str, axis: str, name: str, projects: Projects) -> Response:
    made = CaptureStore(projects.store).open(project, axis, name)
    return file_download(capture_csv(made), "text/csv", f"{name}.csv")


@router.get(
    SAVED + "/{name}/html",
    response_class=Response,
    summary="A saved capture as a standalone interactive HTML file",
    responses={**error_responses(*SAVED_ERRORS), 200: {"content": {"text/html": {}}}},
    dependencies=[Requires(Level.OPERATOR)],
)
def saved_html(project: str, axis: str, name: str, projects: Projects) -> Response:
    made = CaptureStore(projects.store).open(project, axis, name)
    return file_download(capture_html(made), "text/html", f"{name}.html")


@router.delete(
    SAVED + "/{name}",
    status_code=status.HTTP_204_NO_CONTENT,
    response_class=Response,
    summary="Delete a saved capture (changing the project's records needs Expert, like the project itself)",
    responses=error_responses(*SAVED_ERRORS),
    dependencies=[Requires(Level.EXPERT)],
)
def delete_saved(project: str, axis: str, name: str, projects: Projects) -> Response:
    CaptureStore(projects.store).delete(project, axis, name)
    return Response(status_code=status.HTTP_204_NO_CONTENT)


def _default_name(made: Capture) -> str:
    return made.name or f"capture node{made.drive.node} {made.captured_at.replace(':', '-')}"
