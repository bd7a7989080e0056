"""One drive: typed object read/write, CiA 402 state, faults."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Depends, Header, Query

from servostudio.api.deps import current_user, get_connections, get_motion
from servostudio.api.routes.comm_models import (
    DriveState,
    FaultReportModel,
    ObjectValueModel,
    ObjectWrite,
    ReadMany,
    ReadResult,
    StateRequest,
)
from servostudio.drive.access import Drive
from servostudio.drive.cia402 import State
from servostudio.drive.control import fault_report, read_state, reset_faults, set_state
from servostudio.services.bus import ConnectionManager
from servostudio.services.motion import MotionGuard
from servostudio.services.terminal import read_objects

#: The caller's live motion client (announced by /api/ws/events); required for anything that enables the drive.
MotionClient = Annotated[
    str | None, Header(alias="X-Servo-Client", description="id announced by /api/ws/events; required to enable")
]

router = APIRouter(prefix="/buses/{bus}/nodes/{node}", tags=["drives"], dependencies=[Depends(current_user)])
#: A node not identified yet is identified on first use; ``?device=`` names its device instead (and overrides).
Device = Annotated[
    str | None,
    Query(
        description="device key (xtrapulspac, cd1k, …) overriding the identified one; "
        "by default the node is identified on first use"
    ),
]


def _drive(bus: str, node: int, device: str | None, manager: ConnectionManager) -> Drive:
    return manager.get(bus).drive(node, device)


@router.get(
    "/objects/{key}",
    response_model=ObjectValueModel,
    summary="Read an object by address (0x6041, 0x60F9,2), name, or profile name (statusword)",
)
def read_object(
    bus: str, node: int, key: str, device: Device = None, manager: ConnectionManager = Depends(get_connections)
) -> dict:
    return _drive(bus, node, device, manager).read(key).as_dict()


@router.put(
    "/objects/{key}",
    response_model=ObjectValueModel,
    summary="Write an object; access, type and range are checked before anything is sent",
)
def write_object(
    bus: str,
    node: int,
    key: str,
    request: ObjectWrite,
    device: Device = None,
    manager: ConnectionManager = Depends(get_connections),
    motion: MotionGuard = Depends(get_motion),
    client: MotionClient = None,
) -> dict:
    drive = _drive(bus, node, device, manager)
    motion.check_controlword_write(client, (bus, node), drive, key, request.value)
    return drive.write(key, request.value, request.physical).as_dict()


@router.post("/read", response_model=list[ReadResult], summary="Read several objects of this node at once")
def read_many(
    bus: str, node: int, request: ReadMany, device: Device = None, manager: ConnectionManager = Depends(get_connections)
) -> list[dict]:
    return read_objects(manager.get(bus).drive(node, device), request.objects)


@router.get("/state", response_model=DriveState, summary="CiA 402 state and NMT state")
def get_state(
    bus: str, node: int, device: Device = None, manager: ConnectionManager = Depends(get_connections)
) -> dict:
    connection = manager.get(bus)
    state, statusword = read_state(connection.drive(node, device))
    _report(connection, node, statusword)
    return {
        "node": node,
        "state": state.value if state else None,
        "statusword": statusword,
        "nmt_state": connection.monitor.nmt_state(node) if connection.monitor else None,
    }


@router.put("/state", response_model=DriveState, summary="Walk the CiA 402 state machine to a target state")
def put_state(
    bus: str,
    node: int,
    request: StateRequest,
    device: Device = None,
    manager: ConnectionManager = Depends(get_connections),
    motion: MotionGuard = Depends(get_motion),
    client: MotionClient = None,
) -> dict:
    """Enabling (operation-enabled) needs a live motion client, which then answers for the axis."""
    connection = manager.get(bus)
    drive = connection.drive(node, device)
    target = State.parse(request.target)
    if target is State.OPERATION_ENABLED:
        motion.claim(client, (bus, node))
    else:
        motion.release((bus, node))
    set_state(drive, target)
    state, statusword = read_state(drive)
    _report(connection, node, statusword)
    return {
        "node": node,
        "state": state.value if state else None,
        "statusword": statusword,
        "nmt_state": connection.monitor.nmt_state(node) if connection.monitor else None,
    }


@router.get("/faults", response_model=FaultReportModel, summary="Active faults and warnings with the manual's remedy")
def get_faults(
    bus: str, node: int, device: Device = None, manager: ConnectionManager = Depends(get_connections)
) -> dict:
    return fault_report(manager.get(bus).drive(node, device)).as_dict()


@router.post("/faults/reset", response_model=FaultReportModel, summary="Fault reset (control word bit 7 edge)")
def post_fault_reset(
    bus: str, node: int, device: Device = None, manager: ConnectionManager = Depends(get_connections)
) -> dict:
    connection = manager.get(bus)
    drive = connection.drive(node, device)
    reset_faults(drive)
    report = fault_report(drive)
    _report(connection, node, report.statusword)
    return report.as_dict()


def _report(connection, node: int, statusword: int) -> None:
    """Publish a drive_state event when the state read here differs from the last one known."""
    if connection.monitor is not None:
        connection.monitor.report_statusword(node, statusword)
