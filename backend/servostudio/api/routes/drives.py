"""One drive: typed object read/write, CiA 402 state, faults."""

from __future__ import annotations

from fastapi import APIRouter

from servostudio.api.deps import Motion, NodeDrive, OpenBus
from servostudio.api.errors import error_responses
from servostudio.api.routes.comm_models import (
    DriveState,
    FaultReportModel,
    ObjectValueModel,
    ObjectWrite,
    ReadMany,
    ReadResult,
    StateRequest,
)
from servostudio.api.security import ObjectWriteLevel, Requires
from servostudio.drive.control import fault_report
from servostudio.drive.nmt import known_nmt_state
from servostudio.errors import ErrorKind
from servostudio.services import device_control
from servostudio.services.terminal import read_objects
from servostudio.services.users import Level

#: what talking to a drive may meet: unknown bus/node/object, a refusal, a bus down, no answer
DRIVE_ERRORS = (
    ErrorKind.NOT_FOUND,
    ErrorKind.CONFLICT,
    ErrorKind.REFUSED_FOR_SAFETY,
    ErrorKind.COMMUNICATION,
    ErrorKind.UNAVAILABLE,
    ErrorKind.TIMEOUT,
)
router = APIRouter(
    prefix="/buses/{bus}/nodes/{node}",
    tags=["drives"],
    responses=error_responses(*DRIVE_ERRORS),
)


@router.get(
    "/objects/{key}",
    response_model=ObjectValueModel,
    summary="Read an object by address (0x6041, 0x60F9,2), name, or profile name (statusword)",
    dependencies=[Requires(Level.OPERATOR)],
)
def read_object(key: str, drive: NodeDrive) -> dict:
    return drive.read(key).as_dict()


@router.put(
    "/objects/{key}",
    response_model=ObjectValueModel,
    summary="Write an object; access, type and range are checked before anything is sent",
    dependencies=[Requires(Level.OPERATOR), ObjectWriteLevel],
)
def write_object(key: str, request: ObjectWrite, drive: NodeDrive) -> dict:
    """A motion object (control word, mode, target) needs the axis's armed controller: send X-Servo-Client."""
    return drive.write(key, request.value, request.physical).as_dict()


@router.post(
    "/read",
    response_model=list[ReadResult],
    summary="Read several objects of this node at once",
    dependencies=[Requires(Level.OPERATOR)],
)
def read_many(request: ReadMany, drive: NodeDrive) -> list[dict]:
    return read_objects(drive, request.objects)


@router.get(
    "/state",
    response_model=DriveState,
    response_model_exclude_unset=True,
    summary="CiA 402 state and NMT state",
    dependencies=[Requires(Level.OPERATOR)],
)
def get_state(connection: OpenBus, drive: NodeDrive) -> dict:
    """The NMT state as the node's heartbeat or boot-up said it; without one, the status word just read over SDO
    proves it pre-operational or operational (``nmt_source: sdo``)."""
    return _with_nmt(connection, drive, device_control.drive_state(connection, drive))


@router.put(
    "/state",
    response_model=DriveState,
    summary="Walk the CiA 402 state machine to a target state",
    response_model_exclude_unset=True,
    dependencies=[Requires(Level.MAINTENANCE)],
)
def put_state(request: StateRequest, connection: OpenBus, drive: NodeDrive, motion: Motion) -> dict:
    """Enabling (operation-enabled) needs the axis armed by the caller's live client (X-Servo-Client)."""
    return _with_nmt(connection, drive, device_control.change_state(connection, motion, drive, request.target))


def _with_nmt(connection: OpenBus, drive: NodeDrive, state: dict) -> dict:
    """A CANopen node's state with what is known of its NMT state; a PROFIBUS-DP drive has no NMT: left out."""
    if not drive.profile.canopen:
        return state
    return {**state, **known_nmt_state(connection.nmt_state(drive.node), answered_sdo=True)}


@router.get(
    "/faults",
    response_model=FaultReportModel,
    summary="Active faults and warnings with the manual's remedy",
    dependencies=[Requires(Level.OPERATOR)],
)
def get_faults(drive: NodeDrive) -> dict:
    return fault_report(drive).as_dict()


@router.post(
    "/faults/reset",
    response_model=FaultReportModel,
    summary="Fault reset (control word bit 7 edge)",
    dependencies=[Requires(Level.MAINTENANCE)],
)
def post_fault_reset(connection: OpenBus, drive: NodeDrive) -> dict:
    return device_control.reset_faults(connection, drive).as_dict()
