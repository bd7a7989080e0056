"""Dependencies of the routes, one ``Annotated`` alias each: the caller, the server's state and its parts, and the
bus and drive a path names.

``current_user`` is the one place a caller's identity comes from (``api.auth``: an API token, a browser session,
or the password-less local administrator); the level each route declares (``api.security.Requires``) is checked
against it.
"""

from __future__ import annotations

from typing import Annotated

from fastapi import Depends, Header, Query
from starlette.requests import HTTPConnection

from servostudio.api import auth
from servostudio.api.state import ServerState
from servostudio.drive.access import Drive
from servostudio.od import EdsLibrary
from servostudio.services.audit import Actor, act_as
from servostudio.services.bus import BusConnection, ConnectionManager, EventHub, JobRegistry
from servostudio.services.motion import MotionGuard
from servostudio.services.projects import ProjectService
from servostudio.services.projects.live import LiveProjects
from servostudio.services.scope import ScopeService
from servostudio.services.users import AccessControl, User


def server_state(connection: HTTPConnection) -> ServerState:
    state: ServerState = connection.app.state.server
    return state


Server = Annotated[ServerState, Depends(server_state)]


def access(state: Server) -> AccessControl:
    return state.access


Access = Annotated[AccessControl, Depends(access)]


def current_user(connection: HTTPConnection, control: Access) -> User:
    """The caller (HTTP request or WebSocket); 401 when it is nobody."""
    return auth.identify(connection, control)


Caller = Annotated[User, Depends(current_user)]
#: The caller's live motion client (announced by /api/ws/events): motion requests name it (docs/motion-safety.md).
MotionClient = Annotated[
    str | None, Header(alias="X-Servo-Client", description="id announced by /api/ws/events; required for motion")
]


async def acting_caller(user: Caller, client: MotionClient = None) -> Actor:
    """Who acts in this request, for the motion guard and the audit log, set for everything the request does (jobs
    it starts carry it along).  ``async`` on purpose: it runs in the request's own context, so the value reaches
    the route; the bus, drive and project dependencies depend on it, so no route reaches a drive without it."""
    actor = Actor(user.name, str(user.level), client)
    act_as(actor)
    return actor


Acting = Annotated[Actor, Depends(acting_caller)]


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


def projects(state: Server, actor: Acting) -> ProjectService:
    """The project store, with the caller acting (its writes are logged under the caller's name)."""
    return state.projects


def scope(state: Server) -> ScopeService:
    return state.scope


Library = Annotated[EdsLibrary, Depends(library)]
Connections = Annotated[ConnectionManager, Depends(connections)]
Motion = Annotated[MotionGuard, Depends(motion)]
Jobs = Annotated[JobRegistry, Depends(jobs)]
Events = Annotated[EventHub, Depends(events)]
Projects = Annotated[ProjectService, Depends(projects)]
ScopeCaptures = Annotated[ScopeService, Depends(scope)]


def live_projects(service: Projects, manager: Connections) -> LiveProjects:
    """Projects with the server's buses: a project bus is opened on first use and shared with every client."""
    return LiveProjects(service, manager)


def bus_connection(bus: str, manager: Connections, actor: Acting) -> BusConnection:
    """The open bus the path names, with the caller acting (the motion guard judges its writes for the caller)."""
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
