"""FastAPI dependencies shared by the routers.

Every route and WebSocket takes the caller's identity through `current_user`, so user levels plug in here
without touching the routes. Until they exist the server binds to localhost only and every caller is the
local operator.
"""

from __future__ import annotations

from dataclasses import dataclass

from fastapi import Request

from servostudio.od import EdsLibrary


@dataclass(frozen=True)
class User:
    """Who is calling and at which level (the manual's levels arrive with the user-management issue)."""

    name: str
    level: str


LOCAL_OPERATOR = User(name="local", level="administrator")


def current_user() -> User:
    return LOCAL_OPERATOR


def eds_library(request: Request) -> EdsLibrary:
    """The dictionary library of this server (built-in `eds/` plus the user directory)."""
    return request.app.state.eds_library
