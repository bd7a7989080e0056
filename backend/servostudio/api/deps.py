"""Dependencies shared by the routers: the caller's identity and the communication server's state.

``current_user`` is the one place a caller's identity comes from; every router and WebSocket depends on it, so
user levels (the manual's password-protected levels) plug in here later without touching the routes.  The
server binds to localhost only, so today every caller is the local administrator.
"""

from __future__ import annotations

from collections.abc import AsyncIterator
from contextlib import asynccontextmanager
from dataclasses import dataclass

from fastapi import FastAPI
from starlette.requests import HTTPConnection

from servostudio.od import EdsLibrary
from servostudio.services.bus import ConnectionManager, EventHub, JobRegistry
from servostudio.services.motion import MotionGuard


@dataclass(frozen=True)
class User:
    name: str
    level: str


LOCAL_ADMINISTRATOR = User(name="local", level="administrator")


def current_user(connection: HTTPConnection) -> User:
    """The caller (HTTP request or WebSocket)."""
    return LOCAL_ADMINISTRATOR


def eds_library(connection: HTTPConnection) -> EdsLibrary:
    """The dictionary library of this server (built-in `eds/` plus the user directory)."""
    return connection.app.state.eds_library


def get_connections(connection: HTTPConnection) -> ConnectionManager:
    return connection.app.state.connections


def get_motion(connection: HTTPConnection) -> MotionGuard:
    return connection.app.state.motion


def get_jobs(connection: HTTPConnection) -> JobRegistry:
    return connection.app.state.jobs


def get_events(connection: HTTPConnection) -> EventHub:
    return connection.app.state.connections.events


def install_communication(app: FastAPI, buses: list[str]) -> None:
    """Give the app its connection manager and jobs; open ``buses`` at startup, close everything at shutdown."""
    manager = ConnectionManager(getattr(app.state, "eds_library", None))
    app.state.connections = manager
    app.state.motion = MotionGuard()
    app.state.jobs = JobRegistry(manager.events)
    previous = app.router.lifespan_context

    @asynccontextmanager
    async def lifespan(application: FastAPI) -> AsyncIterator[None]:
        for spec in buses:
            manager.open(spec, wait=0.0)
        async with previous(application):
            yield
        manager.close_all()

    app.router.lifespan_context = lifespan
