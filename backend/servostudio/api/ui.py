"""The browser UI at every path no route answers, and a JSON 404 for an unknown ``/api/…`` path.

The UI is the router's fallback (``Router.default``), not a catch-all route: a known API path called with the wrong
method still answers 405, and an unknown API path answers the taxonomy's 404 body instead of the web page.
"""

from __future__ import annotations

from pathlib import Path

from fastapi import FastAPI
from fastapi.responses import FileResponse, HTMLResponse
from fastapi.staticfiles import StaticFiles
from starlette.responses import Response
from starlette.types import ASGIApp, Receive, Scope, Send

from servostudio.errors import NotFound

UI_METHODS = frozenset({"GET", "HEAD"})
NOT_BUILT = "<h1>Servo Studio</h1><p>The browser UI is not built: run <code>make run</code>.</p>"


class UnknownRoute(NotFound):
    """No API route has this path (or the UI was asked for something other than a page)."""


def mount_ui(app: FastAPI, static_dir: Path) -> None:
    """Serve the built UI's assets, and its page at every other path (client-side routing)."""
    assets = static_dir / "assets"
    if assets.is_dir():
        app.mount("/assets", StaticFiles(directory=assets), name="assets")
    app.router.default = _fallback(static_dir)


def _fallback(static_dir: Path) -> ASGIApp:
    async def fallback(scope: Scope, receive: Receive, send: Send) -> None:
        path = scope["path"]
        if scope["type"] != "http" or scope["method"] not in UI_METHODS or _is_api(path):
            raise UnknownRoute(f"no route {scope.get('method', 'WEBSOCKET')} {path}")
        await _page(static_dir, path)(scope, receive, send)

    return fallback


def _is_api(path: str) -> bool:
    return path == "/api" or path.startswith("/api/")


def _page(static_dir: Path, path: str) -> Response:
    """A file of the built UI, else its index.html; 503 with how to build it when there is none."""
    index = static_dir / "index.html"
    if not index.is_file():
        return HTMLResponse(NOT_BUILT, status_code=503)
    candidate = (static_dir / path.lstrip("/")).resolve()
    if candidate.is_file() and candidate.is_relative_to(static_dir.resolve()):
        return FileResponse(candidate)
    return FileResponse(index)
