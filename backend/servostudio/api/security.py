"""What every route declares, and the browser-origin checks in front of every request.

**Levels.** Each route names the lowest level it serves in its decorator, ``dependencies=[Requires(Level.EXPERT)]``,
or ``dependencies=[Anyone]`` for the few that must work before a login (health, login, setup). The declaration is
the check itself (a dependency that refuses a lower caller with 403 ``forbidden``), and :func:`declared_levels`
reads it back, so ``tests/api/test_api_levels.py`` fails on a route that declares nothing and calls every route
with every level. Object writes check the object's own level too (:data:`ObjectWriteLevel`); WebSocket messages
are checked against their protocol's table (:func:`require_message`).

**Browser origins.** :class:`BrowserOrigin` refuses, before any route runs, a request or WebSocket upgrade whose
``Host`` is not this machine's loopback names, the address the server was bound to or a configured host (DNS
rebinding: a foreign name resolving to 127.0.0.1), and one whose ``Origin`` is neither the server's own nor a
configured one (a foreign page in the user's browser). Cookie sessions also need the CSRF token (``api.auth``).

No ``from __future__ import annotations`` here: FastAPI reads the annotations of the dependency objects' methods
at run time, and an object has no module namespace to resolve them in.
"""

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any
from urllib.parse import urlsplit

from fastapi import Depends
from fastapi.params import Depends as DependsParam
from starlette.datastructures import Headers
from starlette.requests import HTTPConnection
from starlette.responses import JSONResponse
from starlette.types import ASGIApp, Receive, Scope, Send

from servostudio.api.deps import Caller, NodeDrive
from servostudio.api.errors import error_body
from servostudio.errors import Forbidden, ServoStudioError
from servostudio.services.settings import Settings
from servostudio.services.users import Level, User, check_write, is_loopback, require
from servostudio.services.users.levels import LevelTooLow

# ---- declared levels ----------------------------------------------------------------------------------------------


class Declared:
    """A route's declared level (None: anyone, before any login); the dependency object enforcing it."""

    level: Level | None = None


class _Anyone(Declared):
    def __call__(self) -> None:
        return None


class _Requires(Declared):
    def __init__(self, level: Level) -> None:
        self.level = self.required = level

    def __call__(self, caller: Caller, connection: HTTPConnection) -> None:
        method = connection.scope.get("method", "WEBSOCKET")
        require(caller, self.required, f"{method} {connection.url.path}")


def Requires(level: Level) -> Any:
    """The route serves callers of ``level`` and above."""
    return Depends(_Requires(level))


#: the route serves anyone, logged in or not
Anyone: Any = Depends(_Anyone())


def declared_levels(route: object) -> list[Level | None]:
    """What ``route`` (a route, or FastAPI's ``RouteContext`` of an included one) declares: one entry expected, an
    empty list is a route nobody thought about."""
    dependencies: list[DependsParam] = getattr(route, "dependencies", [])
    declarations: list[object] = [dep.dependency for dep in dependencies]
    return [declared.level for declared in declarations if isinstance(declared, Declared)]


def _object_write_allowed(key: str, drive: NodeDrive, caller: Caller) -> None:
    check_write(caller, drive.variable(key))


#: an object write also needs the object's own level (``services.users.levels.WRITE_RULES``)
ObjectWriteLevel: Any = Depends(_object_write_allowed)


def require_message(caller: User, table: Mapping[str, Level], kind: str, protocol: str) -> None:
    """A WebSocket message of ``kind`` needs its table's level (a kind the table lacks is the protocol's to
    refuse as unknown)."""
    level = table.get(kind)
    if level is not None:
        require(caller, level, f"{protocol} {kind!r}")


# ---- Host and Origin -------------------------------------------------------------------------------------------

WILDCARD_BINDS = frozenset({"", "0.0.0.0", "::", "[::]"})


class HostRefused(Forbidden):
    """The Host header names another machine: a page of a foreign name that resolves to this server."""


class OriginRefused(Forbidden):
    """The request comes from a page of another origin."""


@dataclass(frozen=True)
class OriginPolicy:
    hosts: frozenset[str]  # besides every loopback name and address
    origins: frozenset[str]  # besides the server's own

    @classmethod
    def of(cls, settings: Settings) -> "OriginPolicy":
        hosts = {*settings.allowed_hosts, *({settings.host} - WILDCARD_BINDS)}
        return cls(frozenset(host.lower().strip("[]") for host in hosts), frozenset(settings.allowed_origins))

    def refusal(self, scope: Scope) -> ServoStudioError | None:
        headers = Headers(scope=scope)
        host = headers.get("host", "")
        if not self._host_allowed(host):
            return HostRefused(f"Host {host!r} is not this server's name; add it with --allowed-host")
        origin = headers.get("origin")
        if origin is not None and not self._origin_allowed(origin, scope, host):
            return OriginRefused(f"requests from pages of {origin} are refused; allow one with --allowed-origin")
        return None

    def _host_allowed(self, host: str) -> bool:
        try:
            name = (urlsplit(f"//{host}").hostname or "").rstrip(".")
        except ValueError:
            return False
        return bool(name) and (is_loopback(name) or name in self.hosts)

    def _origin_allowed(self, origin: str, scope: Scope, host: str) -> bool:
        scheme = "https" if scope.get("scheme") in ("https", "wss") else "http"
        return origin in self.origins or origin.lower() == f"{scheme}://{host.lower()}"


class BrowserOrigin:
    """ASGI middleware: the Host and Origin checks of :class:`OriginPolicy` on every request and upgrade."""

    def __init__(self, app: ASGIApp, policy: OriginPolicy) -> None:
        self.app, self.policy = app, policy

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        refusal = self.policy.refusal(scope) if scope["type"] in ("http", "websocket") else None
        if refusal is None:
            await self.app(scope, receive, send)
        elif scope["type"] == "websocket" and "websocket.http.response" not in scope.get("extensions", {}):
            await send({"type": "websocket.close", "code": 1008, "reason": str(refusal)[:120]})
        else:  # an HTTP answer (for a WebSocket: the denial response) with the taxonomy's body
            await JSONResponse(error_body(refusal), refusal.outcome.http_status)(scope, receive, send)


__all__ = [
    "Anyone",
    "BrowserOrigin",
    "LevelTooLow",
    "ObjectWriteLevel",
    "OriginPolicy",
    "Requires",
    "declared_levels",
    "require_message",
]
