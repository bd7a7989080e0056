"""FastAPI application factory.

:func:`create_app` builds the server's whole state (``ServerState``) from its ``Settings``, so tests and the CLI
create apps with their own; routers stay thin and reach the state through ``api.deps``.
"""

from __future__ import annotations

from collections.abc import AsyncIterator
from contextlib import asynccontextmanager

from fastapi import FastAPI
from starlette.middleware import Middleware

from servostudio import __version__
from servostudio.api.auth import announce_setup
from servostudio.api.errors import EXCEPTION_HANDLERS, RequestIds, error_responses
from servostudio.api.limits import BodyLimits
from servostudio.api.routes import (
    audit,
    backup,
    buses,
    control,
    dictionaries,
    drives,
    events,
    frequency,
    frequency_saved,
    health,
    identification,
    io,
    motion,
    procedures,
    projects,
    report,
    scope,
    sequences,
    server,
    speed_loop,
    users,
)
from servostudio.api.security import BrowserOrigin, OriginPolicy
from servostudio.api.state import ServerState
from servostudio.api.ui import mount_ui
from servostudio.errors import ErrorKind
from servostudio.services.sequences import SequenceMonitors
from servostudio.services.settings import Settings

__all__ = ["Settings", "create_app"]


def create_app(settings: Settings | None = None) -> FastAPI:
    state = ServerState.build(settings or Settings())
    app = FastAPI(
        title="Servo Studio",
        version=__version__,
        description="Communication server of Servo Studio: buses, drives, parameters, projects.",
        lifespan=_lifespan,
        exception_handlers=EXCEPTION_HANDLERS,
        middleware=[
            Middleware(RequestIds),
            Middleware(BrowserOrigin, policy=OriginPolicy.of(state.settings)),
            Middleware(BodyLimits),
        ],
        responses=error_responses(ErrorKind.INVALID_INPUT, ErrorKind.INTERNAL),
    )
    app.state.server = state
    app.state.sequences = SequenceMonitors()  # the live sequence monitors (routes/sequences.py)
    for router in (
        health,
        users,
        dictionaries,
        projects,
        report,
        buses,
        drives,
        control,
        motion,
        procedures,
        identification,
        backup,
        scope,
        sequences,
        io,
        events,
        audit,
        server,
        speed_loop,
        frequency_saved,
        frequency,
    ):
        app.include_router(router.router, prefix="/api")
    mount_ui(app, state.settings.static_dir)
    return app


@asynccontextmanager
async def _lifespan(app: FastAPI) -> AsyncIterator[None]:
    """Open the buses the server was started with (and print the first start's setup link); close every bus at
    shutdown."""
    state: ServerState = app.state.server
    announce_setup(state.access, state.settings)
    state.projects.store.remove_stale_temporaries()  # what saves interrupted by a crash left behind
    state.open_buses()
    yield
    app.state.sequences.close()
    state.close()
