"""The quick test's motions: jog (profile velocity), move (profile position), home, stop, and their limits.

Each motion needs the caller's live client (``X-Servo-Client``) to be the axis's armed controller (409 otherwise)
and stays within the axis's limits (422 above them, nothing written); ``"hold": true`` makes it hold-to-run: it
quick-stops when the client's keepalive (``{"type": "keepalive", "bus", "node"}`` on its ``/api/ws/events``)
stops arriving.  Stopping needs no controller.  The service is ``services.motion.jog``; the rules are in
``docs/motion-safety.md``.
"""

from __future__ import annotations

from typing import Annotated, Literal

from fastapi import APIRouter, Path
from pydantic import BaseModel, Field

from servostudio.api.deps import Acting, Motion, NodeDrive, OpenBus
from servostudio.api.errors import error_responses
from servostudio.api.routes.drives import DRIVE_ERRORS
from servostudio.api.security import Requires
from servostudio.drive.profiles import profile_for
from servostudio.errors import ErrorKind, NotFound
from servostudio.services.users import Level

router = APIRouter(tags=["motion"], responses=error_responses(*DRIVE_ERRORS))
AXIS = "/buses/{bus}/nodes/{node}/motion"
Node = Annotated[int, Path(ge=1, le=127, description="node ID")]
Hold = Annotated[bool, Field(description="hold-to-run: quick stop when the client's keepalive stops arriving")]


class JogBody(BaseModel):
    velocity: float = Field(description="rpm; the sign is the direction", examples=[60.0])
    seconds: float | None = Field(default=None, description="how long; null: for as long as the hold lasts")
    hold: Hold = False


class MoveBody(BaseModel):
    distance: float = Field(description="user position units: relative, or the target with absolute", examples=[4096])
    absolute: bool = False
    velocity: float | None = Field(default=None, description="rpm; null: 60 rpm (capped by the limit)")
    hold: Hold = False


class HomeBody(BaseModel):
    method: int = Field(description="homing method (0x6098), see GET /api/homing-methods/{device}", examples=[35])
    hold: Hold = False
    velocity: float | None = Field(default=None, description="rpm of the switch search; null: the drive's 0x6099")


class MotionModel(BaseModel):
    motion: str | None = Field(description="the motion's id; null: a stop with no motion running")
    bus: str
    node: int
    state: Literal["running", "done", "stopped", "failed"]
    reason: str | None = Field(description="why it stopped or failed")
    kind: Literal["jog", "move", "home"] | None = None
    hold: bool | None = None
    client: str | None = Field(default=None, description="the controller's client that started it")
    request: dict[str, float | bool | int | None] | None = None
    started: float | None = Field(default=None, description="Unix time")
    ended: float | None = Field(default=None, description="Unix time")
    last_keepalive: float | None = Field(default=None, description="Unix time the last keepalive arrived")
    position: int | None = Field(default=None, description="0x6064 when it ended")
    statusword: int | None = None


class LimitsModel(BaseModel):
    velocity_rpm: float = Field(description="fastest jog, move or homing speed")
    distance_revolutions: float = Field(description="longest move")
    seconds: float = Field(description="longest timed jog")


class LimitsBody(BaseModel):
    velocity_rpm: float | None = None
    distance_revolutions: float | None = None
    seconds: float | None = None


class HomingMethodModel(BaseModel):
    method: int = Field(examples=[35])
    description: str = Field(description="the manual's description")


def _moving(summary: str) -> dict:
    return {
        "response_model": MotionModel,
        "summary": summary,
        "dependencies": [Requires(Level.EXPERT)],  # "motion" is the Expert's (docs/security.md)
        "responses": error_responses(ErrorKind.REFUSED_FOR_SAFETY, ErrorKind.INVALID_INPUT),
    }


@router.post(f"{AXIS}/jog", **_moving("Jog in profile velocity (the armed controller only, within the limits)"))
def jog(body: JogBody, connection: OpenBus, drive: NodeDrive, motion: Motion, actor: Acting) -> dict:
    axis = (connection.id, drive.node)
    return motion.motions.jog(actor, axis, drive, body.velocity, body.seconds, body.hold)


@router.post(f"{AXIS}/move", **_moving("Move in profile position, relative or absolute"))
def move(body: MoveBody, connection: OpenBus, drive: NodeDrive, motion: Motion, actor: Acting) -> dict:
    axis = (connection.id, drive.node)
    return motion.motions.move(actor, axis, drive, body.distance, body.absolute, body.velocity, body.hold)


@router.post(f"{AXIS}/home", **_moving("Home the axis with a method"))
def home(body: HomeBody, connection: OpenBus, drive: NodeDrive, motion: Motion, actor: Acting) -> dict:
    axis = (connection.id, drive.node)
    return motion.motions.home(actor, axis, drive, body.method, body.hold, body.velocity)


@router.post(
    f"{AXIS}/stop",
    response_model=MotionModel,
    summary="Quick stop (anyone may stop an axis)",
    dependencies=[Requires(Level.MAINTENANCE)],
)
def stop(connection: OpenBus, drive: NodeDrive, motion: Motion, actor: Acting) -> dict:
    return motion.motions.stop(actor, (connection.id, drive.node), drive)


@router.get(
    AXIS,
    response_model=MotionModel | None,
    summary="The axis's running (else last) motion; null: none",
    dependencies=[Requires(Level.OPERATOR)],
)
def current(node: Node, connection: OpenBus, motion: Motion) -> dict | None:
    return motion.motions.current((connection.id, node))


@router.get(
    f"{AXIS}/limits",
    response_model=LimitsModel,
    summary="The axis's quick-test limits",
    dependencies=[Requires(Level.OPERATOR)],
)
def get_limits(node: Node, connection: OpenBus, motion: Motion) -> dict:
    return motion.motions.limits.of((connection.id, node)).as_dict()


@router.put(
    f"{AXIS}/limits",
    response_model=LimitsModel,
    summary="Raise (or lower) the axis's quick-test limits until the server restarts",
    dependencies=[Requires(Level.EXPERT)],
)
def set_limits(body: LimitsBody, node: Node, connection: OpenBus, motion: Motion) -> dict:
    return motion.motions.limits.set((connection.id, node), **body.model_dump()).as_dict()


@router.get(
    "/homing-methods/{device}",
    response_model=list[HomingMethodModel],
    summary="A device's homing methods with the manual's description of each",
    dependencies=[Requires(Level.OPERATOR)],
)
def homing_methods(device: str) -> list[dict]:
    methods = profile_for(device).homing_methods
    if not methods:
        raise NotFound(f"no homing methods known for device {device!r}")
    return [{"method": number, "description": text} for number, text in sorted(methods.items())]
