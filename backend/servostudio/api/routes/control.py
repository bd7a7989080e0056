"""One controller per axis: who holds an axis, and arming, releasing, asking for and taking over its control.

Every call names the caller's live client (``X-Servo-Client``, announced by ``/api/ws/events``).  The holder of an
axis hears ``control_request`` on its event socket when someone asks; every socket hears ``control`` when the
holder changes.  The rules are in ``docs/motion-safety.md``.
"""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Path
from pydantic import BaseModel, Field

from servostudio.api.deps import Acting, Motion, NodeDrive, OpenBus
from servostudio.api.errors import error_responses
from servostudio.api.routes.drives import DRIVE_ERRORS
from servostudio.api.security import Requires
from servostudio.errors import ErrorKind
from servostudio.services.users import Level

router = APIRouter(tags=["control"], responses=error_responses(ErrorKind.NOT_FOUND, ErrorKind.CONFLICT))
AXIS = "/buses/{bus}/nodes/{node}/control"
Node = Annotated[int, Path(ge=1, le=127, description="node ID")]


class HolderModel(BaseModel):
    client: str = Field(examples=["3f9a1c0de2b47a65"])
    user: str = Field(examples=["local"])
    since: float = Field(description="Unix time it armed (or asked for) the axis")


class AxisControlModel(BaseModel):
    bus: str = Field(examples=["sim"])
    node: int = Field(examples=[1])
    holder: HolderModel | None = Field(description="the axis's controller; null: nobody holds it")
    requests: list[HolderModel] = Field(description="clients that asked the holder for the axis")


@router.get(
    "/control",
    response_model=list[AxisControlModel],
    summary="Every armed axis and its controller",
    dependencies=[Requires(Level.OPERATOR)],
)
def list_controls(motion: Motion) -> list[dict]:
    return motion.controls()


@router.get(
    AXIS, response_model=AxisControlModel, summary="Who holds the axis", dependencies=[Requires(Level.OPERATOR)]
)
def get_control(node: Node, connection: OpenBus, motion: Motion) -> dict:
    return motion.control((connection.id, node))


@router.post(
    f"{AXIS}/arm",
    response_model=AxisControlModel,
    summary="Arm the axis: the caller's client becomes its controller (409 naming the holder if another has it)",
    dependencies=[Requires(Level.MAINTENANCE)],
    responses=error_responses(ErrorKind.REFUSED_FOR_SAFETY),
)
def arm(node: Node, connection: OpenBus, motion: Motion, actor: Acting) -> dict:
    return motion.arm(actor, (connection.id, node))


@router.post(
    f"{AXIS}/release",
    response_model=AxisControlModel,
    summary="Disarm the axis; if it is still enabled it gets a quick stop",
    dependencies=[Requires(Level.MAINTENANCE)],
    responses=error_responses(*DRIVE_ERRORS),
)
def release(connection: OpenBus, drive: NodeDrive, motion: Motion, actor: Acting) -> dict:
    return motion.release(actor, (connection.id, drive.node), drive)


@router.post(
    f"{AXIS}/request",
    response_model=AxisControlModel,
    summary="Ask the axis's controller (over its event socket) to release the axis",
    dependencies=[Requires(Level.MAINTENANCE)],
    responses=error_responses(ErrorKind.REFUSED_FOR_SAFETY),
)
def request(node: Node, connection: OpenBus, motion: Motion, actor: Acting) -> dict:
    return motion.request(actor, (connection.id, node))


@router.post(
    f"{AXIS}/take-over",
    response_model=AxisControlModel,
    summary="Take the axis over from its controller (Expert; logged; the axis keeps its state)",
    dependencies=[Requires(Level.EXPERT)],
    responses=error_responses(ErrorKind.REFUSED_FOR_SAFETY, ErrorKind.FORBIDDEN),
)
def take_over(node: Node, connection: OpenBus, motion: Motion, actor: Acting) -> dict:
    return motion.take_over(actor, (connection.id, node))
