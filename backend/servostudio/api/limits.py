"""Request body limits per route, refused early with the taxonomy's ``too_large`` (HTTP 413).

A request whose ``Content-Length`` exceeds its route's limit is answered before the body is read and before the
route runs; a body without a length (chunked) or longer than it said is counted as it streams in and refused the
moment it passes the limit, so the server never holds more of a request than the limit.  The route then sees its
body end with `BodyTooLarge`, and whatever it would answer is dropped: the client gets the 413 alone.

A route declares its limit with ``openapi_extra=body_limit(BYTES)``: it is part of the route's OpenAPI operation
(``x-max-body-bytes``, next to its 413 response), which is also where this middleware reads it; every other route
accepts `DEFAULT_BODY_BYTES`.
"""

from __future__ import annotations

import re
from typing import Any

from fastapi.responses import JSONResponse
from starlette.datastructures import Headers
from starlette.routing import compile_path
from starlette.types import ASGIApp, Message, Receive, Scope, Send

from servostudio.api.errors import error_body
from servostudio.errors import TooLarge

MIB = 1024 * 1024
#: JSON requests are a few kilobytes; a megabyte leaves room for the largest (a parameter list, a motor).
DEFAULT_BODY_BYTES = 1 * MIB
LIMIT_KEY = "x-max-body-bytes"


class BodyTooLarge(TooLarge):
    """A request body larger than its route accepts; it was refused before anything of it was kept."""

    def __init__(self, limit: int) -> None:
        super().__init__(f"request body larger than this route's limit of {limit} bytes; nothing was kept")


def body_limit(max_bytes: int) -> dict[str, object]:
    """``openapi_extra`` of a route that accepts bodies up to ``max_bytes`` (instead of `DEFAULT_BODY_BYTES`)."""
    return {LIMIT_KEY: max_bytes}


_RouteLimit = tuple[re.Pattern[str], frozenset[str], int]


class BodyLimits:
    """ASGI middleware enforcing each route's body limit (see the module)."""

    def __init__(self, app: ASGIApp) -> None:
        self.app = app
        self._limits: list[_RouteLimit] | None = None

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        limit = self._limit_of(scope)
        declared = _content_length(scope)
        if declared is not None and declared > limit:
            await _refusal(limit)(scope, receive, send)
            return
        body = _CountedBody(scope, receive, send, limit)
        await self.app(scope, body.receive, body.send)

    def _limit_of(self, scope: Scope) -> int:
        """The limit of the route the request is for (from the app's OpenAPI schema, read once: its routes are
        fixed by the first request)."""
        if self._limits is None:
            self._limits = _declared_limits(scope["app"].openapi())
        method, path = scope["method"], scope["path"]
        for pattern, methods, limit in self._limits:
            if method in methods and pattern.match(path):
                return limit
        return DEFAULT_BODY_BYTES


class _CountedBody:
    """One request's body, counted as it arrives; past the limit the 413 goes out and the app's answer is dropped."""

    def __init__(self, scope: Scope, receive: Receive, send: Send, limit: int) -> None:
        self.scope, self._receive, self._send, self.limit = scope, receive, send, limit
        self.received = 0
        self.refused = False
        self.answering = False

    async def receive(self) -> Message:
        message = await self._receive()
        if message["type"] == "http.request":
            self.received += len(message.get("body", b""))
            if self.received > self.limit:
                await self._refuse()
        return message

    async def send(self, message: Message) -> None:
        if self.refused:
            return
        self.answering = True
        await self._send(message)

    async def _refuse(self) -> None:
        """Answer 413 (unless the app already started its answer) and end the app's reading of the body."""
        if not self.refused and not self.answering:
            self.refused = True
            await _refusal(self.limit)(self.scope, self._receive, self._send)
        raise BodyTooLarge(self.limit)


def _declared_limits(schema: dict[str, Any]) -> list[_RouteLimit]:
    return [
        (compile_path(path)[0], frozenset({method.upper()}), int(operation[LIMIT_KEY]))
        for path, operations in schema["paths"].items()
        for method, operation in operations.items()
        if LIMIT_KEY in operation
    ]


def _refusal(limit: int) -> JSONResponse:
    error = BodyTooLarge(limit)
    return JSONResponse(error_body(error), status_code=error.outcome.http_status)


def _content_length(scope: Scope) -> int | None:
    try:
        return int(Headers(scope=scope)["content-length"])
    except (KeyError, ValueError):
        return None
