"""FastAPI application factory.

The app is built by :func:`create_app` so tests and the CLI create it with their own settings;
routers stay thin and receive what they need through dependencies.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from fastapi import FastAPI
from fastapi.responses import FileResponse, HTMLResponse
from fastapi.staticfiles import StaticFiles

from servostudio import __version__
from servostudio.api.deps import install_communication
from servostudio.api.routes import backup, buses, dictionaries, drives, events, health, projects, users
from servostudio.api.routes.errors import register_error_handlers
from servostudio.od import BUILTIN_EDS_DIR, EdsLibrary
from servostudio.od.library import DEFAULT_USER_EDS_DIR

STATIC_DIR = Path(__file__).resolve().parent.parent / "static"


@dataclass
class Settings:
    """What the server was started with."""

    projects_dir: Path = field(default_factory=lambda: Path("projects"))
    static_dir: Path = STATIC_DIR
    user_eds_dir: Path = DEFAULT_USER_EDS_DIR
    buses: list[str] = field(default_factory=list)  # bus specs opened at startup


def create_app(settings: Settings | None = None) -> FastAPI:
    settings = settings or Settings()
    app = FastAPI(
        title="Servo Studio",
        version=__version__,
        description="Communication server of Servo Studio: buses, drives, parameters, projects.",
    )
    app.state.settings = settings
    app.state.eds_library = EdsLibrary(BUILTIN_EDS_DIR, settings.user_eds_dir)
    app.include_router(health.router, prefix="/api")
    app.include_router(users.router, prefix="/api")
    app.include_router(dictionaries.router, prefix="/api")
    app.include_router(projects.router, prefix="/api")
    install_communication(app, settings.buses)
    register_error_handlers(app)
    for router in (buses.router, drives.router, backup.router, events.router):
        app.include_router(router, prefix="/api")
    _mount_ui(app, settings.static_dir)
    return app


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
