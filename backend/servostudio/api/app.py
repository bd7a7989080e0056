"""FastAPI application factory.

:func:`create_app` builds the server's whole state (``ServerState``) from its ``Settings``, so tests and the CLI
create apps with their own; routers stay thin and reach the state through ``api.deps``.
"""

from __future__ import annotations

from collections.abc import AsyncIterator
from contextlib import asynccontextmanager
from pathlib import Path

from fastapi import FastAPI
from fastapi.responses import FileResponse, HTMLResponse
from fastapi.staticfiles import StaticFiles
from starlette.middleware import Middleware

from servostudio import __version__
from servostudio.api.errors import EXCEPTION_HANDLERS, RequestIds, error_responses
from servostudio.api.routes import backup, buses, dictionaries, drives, events, health, projects, users
from servostudio.api.state import ServerState
from servostudio.errors import ErrorKind
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
        middleware=[Middleware(RequestIds)],
        responses=error_responses(ErrorKind.INVALID_INPUT, ErrorKind.INTERNAL),
    )
    app.state.server = state
    for router in (health, users, dictionaries, projects, buses, drives, backup, events):
        app.include_router(router.router, prefix="/api")
    _mount_ui(app, state.settings.static_dir)
    return app


@asynccontextmanager
async def _lifespan(app: FastAPI) -> AsyncIterator[None]:
    """Open the buses the server was started with; close every bus at shutdown."""
    state: ServerState = app.state.server
    state.open_buses()
    yield
    state.close()


def _mount_ui(app: FastAPI, static_dir: Path) -> None:
    """Serve the built browser UI; every non-API path falls back to index.html (client-side routing)."""
    index = static_dir / "index.html"
    if not index.is_file():

        @app.get("/", include_in_schema=False)
        def ui_missing() -> HTMLResponse:
            return HTMLResponse(
                "<h1>Servo Studio</h1><p>The browser UI is not built: run <code>make run</code>.</p>",
                status_code=503,
            )

        return
    assets = static_dir / "assets"
    if assets.is_dir():
        app.mount("/assets", StaticFiles(directory=assets), name="assets")

    @app.get("/{path:path}", include_in_schema=False)
    def ui(path: str) -> FileResponse:
        candidate = (static_dir / path).resolve()
        if path and candidate.is_file() and candidate.is_relative_to(static_dir.resolve()):
            return FileResponse(candidate)
        return FileResponse(index)
