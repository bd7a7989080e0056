"""Dependencies of the routes, one ``Annotated`` alias each: the caller, the server's state and its parts, and the
bus and drive a path names.

``current_user`` is the one place a caller's identity comes from; every router and WebSocket depends on it, so
user levels (the manual's password-protected levels) plug in here later without touching the routes.  The
server binds to localhost only, so today every caller is the local administrator.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Annotated

from fastapi import Depends, Header, Query
from starlette.requests import HTTPConnection

from servostudio.api.state import ServerState
from servostudio.drive.access import Drive
from servostudio.od import EdsLibrary
from servostudio.services.bus import BusConnection, ConnectionManager, EventHub, JobRegistry
from servostudio.services.motion import MotionGuard
from servostudio.services.projects import ProjectService
from servostudio.services.projects.live import LiveProjects


@dataclass(frozen=True)
class User:
    name: str
    level: str


LOCAL_ADMINISTRATOR = User(name="local", level="administrator")


def current_user(connection: HTTPConnection) -> User:
    """The caller (HTTP request or WebSocket)."""
    return LOCAL_ADMINISTRATOR


def server_state(connection: HTTPConnection) -> ServerState:
    state: ServerState = connection.app.state.server
    return state


Caller = Annotated[User, Depends(current_user)]
Server = Annotated[ServerState, Depends(server_state)]


def library(state: Server) -> EdsLibrary:
    return state.library


def connections(state: Server) -> ConnectionManager:
    return state.connections


def motion(state: Server) -> MotionGuard:
    return state.motion


def jobs(state: Server) -> JobRegistry:
    return state.jobs


def events(state: Server) -> EventHub:
    return state.events


def projects(state: Server) -> ProjectService:
    return state.projects


Library = Annotated[EdsLibrary, Depends(library)]
Connections = Annotated[ConnectionManager, Depends(connections)]
Motion = Annotated[MotionGuard, Depends(motion)]
Jobs = Annotated[JobRegistry, Depends(jobs)]
Events = Annotated[EventHub, Depends(events)]
Projects = Annotated[ProjectService, Depends(projects)]


def live_projects(service: Projects, manager: Connections) -> LiveProjects:
    """Projects with the server's buses: a project bus is opened on first use and shared with every client."""
    return LiveProjects(service, manager)


def bus_connection(bus: str, manager: Connections) -> BusConnection:
    """The open bus the path names."""
    return manager.get(bus)


Live = Annotated[LiveProjects, Depends(live_projects)]
OpenBus = Annotated[BusConnection, Depends(bus_connection)]
#: ``?device=`` names the node's device instead of identifying it on first use (and overrides the identified one).
DeviceKey = Annotated[
    str | None,
    Query(
        description="device key (xtrapulspac, cd1k, …) overriding the identified one; "
        "by default the node is identified on first use",
    ),
]


def node_drive(node: int, connection: OpenBus, device: DeviceKey = None) -> Drive:
    """The drive the path's bus and node name."""
    return connection.drive(node, device)


NodeDrive = Annotated[Drive, Depends(node_drive)]
#: The caller's live motion client (announced by /api/ws/events); required for anything that enables the drive.
MotionClient = Annotated[
    str | None, Header(alias="X-Servo-Client", description="id announced by /api/ws/events; required to enable")
]
