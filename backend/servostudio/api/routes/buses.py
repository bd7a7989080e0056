"""Buses: open, list, close, scan, NMT.  Routes are plain ``def``: FastAPI runs them in its thread pool, so the
blocking drive calls never stall the event loop."""

from __future__ import annotations

from fastapi import APIRouter, Response, status

from servostudio.api.deps import Connections, OpenBus
from servostudio.api.errors import error_responses
from servostudio.api.routes.comm_models import (
    BusMatchModel,
    BusMatchRequest,
    BusOpen,
    BusStatus,
    NmtRequest,
    NodeIdentity,
    OpenedBus,
    ShareModel,
    ShareRequest,
)
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
    response_model=OpenedBus,
    status_code=status.HTTP_201_CREATED,
    summary="Open a bus from a spec string: 201 opened; 200 with existing: true when that spec is open already "
    "(without id or under the same id); 409 naming the open bus when another id is asked for",
    responses={200: {"model": OpenedBus, "description": "the spec was open already: that bus, existing: true"}},
    dependencies=[Requires(Level.MAINTENANCE)],
)
def open_bus(request: BusOpen, manager: Connections, response: Response) -> dict:
    connection, existing = manager.opened(request.spec, request.id)
    if existing:
        response.status_code = status.HTTP_200_OK
    return {**connection.status(), "existing": existing}


@router.post(
    "/match",
    response_model=list[BusMatchModel],
    summary="Which open bus each project bus is: by spec (any spelling) first, else by name",
    dependencies=[Requires(Level.OPERATOR)],
)
def match_buses(request: BusMatchRequest, manager: Connections) -> list[dict]:
    return [manager.match(bus.name, bus.spec).as_dict() for bus in request.buses]


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
    summary="Find and identify every node (1–127; 1–63 on a serial link; DP stations 3–125 on a PROFIBUS line)",
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
    """Judged by the motion guard for every node it reaches and logged as writes are: a start of an enabled axis
    needs its armed controller (409 otherwise); a reset of an enabled axis is a stop (docs/motion-safety.md)."""
    connection.nmt(request.command, request.node)


@router.get(
    "/{bus}/share",
    response_model=ShareModel,
    summary="The bus's socketcand endpoint for the user's own CANopen scripts (404 when not shared)",
    dependencies=[Requires(Level.OPERATOR)],
)
def get_share(connection: OpenBus) -> dict:
    return connection.shared().as_dict()


@router.put(
    "/{bus}/share",
    response_model=ShareModel,
    summary="Share the bus as a socketcand endpoint on a loopback address (python canopen / python-can beside the UI)",
    responses=error_responses(ErrorKind.INVALID_INPUT),
    dependencies=[Requires(Level.EXPERT)],
)
def put_share(request: ShareRequest, connection: OpenBus) -> dict:
    """SDO requests of the clients are answered by the server's SDO engine in turn (one SDO client per channel);
    their writes pass the motion guard; NMT and SYNC go on the bus, other client frames are dropped."""
    return connection.share_on(request.host, request.port).as_dict()


@router.delete(
    "/{bus}/share",
    status_code=status.HTTP_204_NO_CONTENT,
    summary="Stop sharing the bus (its clients are disconnected)",
    dependencies=[Requires(Level.EXPERT)],
)
def delete_share(connection: OpenBus) -> None:
    connection.share_off()
