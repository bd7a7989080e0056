"""Buses: open, list, close, scan, NMT.  Routes are plain ``def``: FastAPI runs them in its thread pool, so the
blocking drive calls never stall the event loop."""

from __future__ import annotations

from fastapi import APIRouter, Depends, status

from servostudio.api.deps import Connections, OpenBus, current_user
from servostudio.api.errors import error_responses
from servostudio.api.routes.comm_models import BusOpen, BusStatus, NmtRequest, NodeIdentity
from servostudio.errors import ErrorKind
from servostudio.services.scan import scan

router = APIRouter(
    prefix="/buses",
    tags=["buses"],
    dependencies=[Depends(current_user)],
    responses=error_responses(ErrorKind.NOT_FOUND, ErrorKind.CONFLICT, ErrorKind.UNAVAILABLE),
)


@router.get("", response_model=list[BusStatus], summary="Open buses with their connection state and known nodes")
def list_buses(manager: Connections) -> list[dict]:
    return [bus.status() for bus in manager.list()]


@router.post(
    "",
    response_model=BusStatus,
    status_code=status.HTTP_201_CREATED,
    summary="Open a bus from a spec string (an existing bus with the same spec is returned)",
)
def open_bus(request: BusOpen, manager: Connections) -> dict:
    return manager.open(request.spec, request.id).status()


@router.get("/{bus}", response_model=BusStatus, summary="One bus")
def get_bus(connection: OpenBus) -> dict:
    return connection.status()


@router.delete("/{bus}", status_code=status.HTTP_204_NO_CONTENT, summary="Close a bus")
def close_bus(bus: str, manager: Connections) -> None:
    manager.close(bus)


@router.post(
    "/{bus}/scan",
    response_model=list[NodeIdentity],
    summary="Find and identify every node (1–127; 1–63 on a serial link)",
)
def scan_bus(connection: OpenBus) -> list[dict]:
    return [info.as_dict() for info in scan(connection)]


@router.post("/{bus}/nmt", status_code=status.HTTP_204_NO_CONTENT, summary="Send an NMT command")
def nmt(request: NmtRequest, connection: OpenBus) -> None:
    connection.nmt(request.command, request.node)
