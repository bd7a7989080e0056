"""Buses: open, list, close, scan, NMT.  Routes are plain ``def``: FastAPI runs them in its thread pool, so the
blocking drive calls never stall the event loop."""

from __future__ import annotations

from fastapi import APIRouter, Response, status

from servostudio.api.deps import Connections, OpenBus
from servostudio.api.errors import error_responses
from servostudio.api.routes.comm_models import BusOpen, BusStatus, NmtRequest, NodeIdentity
from servostudio.api.security import Requires
from servostudio.errors import ErrorKind
from servostudio.services.scan import empty_scan_hint, scan
from servostudio.services.users import Level

SCAN_HINT_HEADER = "X-Scan-Hint"
SCAN_HINT = "set when the scan found no node: why the bus may look empty (bit rate, termination, power, channel)"

router = APIRouter(
    prefix="/buses",
    tags=["buses"],
    responses=error_responses(ErrorKind.NOT_FOUND, ErrorKind.CONFLICT, ErrorKind.UNAVAILABLE),
)


@router.get(
    "",
    response_model=list[BusStatus],
    summary="Open buses with their connection state and known nodes",
    dependencies=[Requires(Level.OPERATOR)],
)
def list_buses(manager: Connections) -> list[dict]:
    return [bus.status() for bus in manager.list()]


@router.post(
    "",
    response_model=BusStatus,
    status_code=status.HTTP_201_CREATED,
    summary="Open a bus from a spec string (an existing bus with the same spec is returned)",
    dependencies=[Requires(Level.MAINTENANCE)],
)
def open_bus(request: BusOpen, manager: Connections) -> dict:
    return manager.open(request.spec, request.id).status()


@router.get("/{bus}", response_model=BusStatus, summary="One bus", dependencies=[Requires(Level.OPERATOR)])
def get_bus(connection: OpenBus) -> dict:
    return connection.status()


@router.delete(
    "/{bus}", status_code=status.HTTP_204_NO_CONTENT, summary="Close a bus", dependencies=[Requires(Level.MAINTENANCE)]
)
def close_bus(bus: str, manager: Connections) -> None:
    manager.close(bus)


@router.post(
    "/{bus}/scan",
    response_model=list[NodeIdentity],
    summary="Find and identify every node (1–127; 1–63 on a serial link)",
    responses={200: {"headers": {SCAN_HINT_HEADER: {"description": SCAN_HINT, "schema": {"type": "string"}}}}},
    dependencies=[Requires(Level.OPERATOR)],
)
def scan_bus(connection: OpenBus, response: Response) -> list[dict]:
    """An empty bus is an answer (200, ``[]``); the header then says why it may look empty."""
    found = [info.as_dict() for info in scan(connection)]
    if not found:
        response.headers[SCAN_HINT_HEADER] = empty_scan_hint(connection)
    return found


@router.post(
    "/{bus}/nmt",
    status_code=status.HTTP_204_NO_CONTENT,
    summary="Send an NMT command",
    dependencies=[Requires(Level.EXPERT)],
)
def nmt(request: NmtRequest, connection: OpenBus) -> None:
    connection.nmt(request.command, request.node)
