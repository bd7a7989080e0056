"""The HTTP side of the error taxonomy (``servostudio.errors``), installed once by ``create_app``.

- A :class:`ServoStudioError` is answered with the status of its kind (``OUTCOMES``) and the body
  ``{"detail": message, "error": class name, "kind": kind}``.
- A request that does not fit its schema: 422, ``detail`` is FastAPI's list of problems, kind ``invalid_input``;
  one whose body cannot be parsed at all (not UTF-8 JSON, a broken form) likewise, as `MalformedBody`, where
  FastAPI would answer a bare 400.
- Any other exception is a bug: logged with its traceback and answered 500 with kind ``internal`` and the request
  id, so a user can quote it.  Never 422: a programming error is not the caller's bad input.

Every HTTP response carries the request id in ``X-Request-ID``.
"""

from __future__ import annotations

import logging
import math
import uuid
from collections.abc import Callable, Coroutine
from typing import Any

from fastapi import Request, Response
from fastapi.encoders import jsonable_encoder
from fastapi.exception_handlers import http_exception_handler
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse
from pydantic import BaseModel, Field
from starlette.datastructures import MutableHeaders
from starlette.exceptions import HTTPException
from starlette.types import ASGIApp, Message, Receive, Scope, Send

from servostudio.errors import OUTCOMES, ErrorKind, InvalidInput, RateLimited, ServoStudioError

REQUEST_ID_HEADER = "X-Request-ID"
log = logging.getLogger(__name__)
#: FastAPI's answer to a body it cannot parse (it raises ``HTTPException(400)``); no route raises 400 itself
_UNPARSABLE_BODY = 400


_JSON = {"application/json": {"schema": {"$ref": "#/components/schemas/ErrorBody"}}}


class MalformedBody(InvalidInput):
    """A request body that could not be parsed at all: nothing of the request was done."""


class ErrorBody(BaseModel):
    """What every refusal and failure of the API answers."""

    detail: str | list[dict[str, Any]] = Field(
        description="what went wrong, naming node, object and reason (a list of problems for a malformed request)",
        examples=["node 1, object 0x6060,0: Value range of parameter exceeded (SDO abort 0x06090030)"],
    )
    error: str = Field(description="the exception class", examples=["SdoAbortError"])
    kind: ErrorKind = Field(description="what the caller can do about it; decides the status")
    request_id: str | None = Field(None, description="internal errors only: quote it, the server log has the details")


def error_responses(*kinds: ErrorKind) -> dict[int | str, dict[str, Any]]:
    """The OpenAPI ``responses=`` of routes that may fail with these kinds (kinds sharing a status share an entry).

    The body is declared as JSON explicitly: FastAPI would file it under the route's own media type, which for a
    text download is ``text/plain``."""
    responses: dict[int | str, dict[str, Any]] = {}
    for kind in kinds:
        outcome = OUTCOMES[kind]
        entry = responses.setdefault(outcome.http_status, {"model": ErrorBody, "description": "", "content": _JSON})
        entry["description"] = "; ".join(filter(None, (entry["description"], f"`{kind}`: {outcome.meaning}")))
    return responses


async def _refused(request: Request, error: ServoStudioError) -> JSONResponse:
    return JSONResponse(error_body(error), status_code=error.outcome.http_status, headers=_retry_after(error))


def _retry_after(error: ServoStudioError) -> dict[str, str]:
    """A rate-limited caller learns when to retry (RFC 9110 §10.2.3: whole seconds)."""
    if isinstance(error, RateLimited):
        return {"Retry-After": str(max(1, math.ceil(error.retry_after)))}
    return {}


async def _malformed(request: Request, error: RequestValidationError) -> JSONResponse:
    body = {"detail": jsonable_encoder(error.errors()), "error": type(error).__name__, "kind": ErrorKind.INVALID_INPUT}
    return JSONResponse(body, status_code=OUTCOMES[ErrorKind.INVALID_INPUT].http_status)


async def _http_error(request: Request, error: HTTPException) -> Response:
    """FastAPI's own 400 for an unparsable body becomes the taxonomy's invalid input; other HTTP errors (an unknown
    path, a method the path does not have) keep FastAPI's answer."""
    if error.status_code == _UNPARSABLE_BODY:
        return await _refused(request, MalformedBody(f"the request body could not be parsed ({error.detail})"))
    return await http_exception_handler(request, error)


#: for ``FastAPI(exception_handlers=…)``
EXCEPTION_HANDLERS: dict[int | type[Exception], Callable[[Request, Any], Coroutine[Any, Any, Response]]] = {
    ServoStudioError: _refused,
    RequestValidationError: _malformed,
    HTTPException: _http_error,
}


def error_body(error: ServoStudioError) -> dict[str, str]:
    """The JSON of a refusal (the WebSocket terminal sends the same fields)."""
    return {"detail": str(error), "error": type(error).__name__, "kind": error.kind}


class RequestIds:
    """ASGI middleware: an id for every HTTP request (response header ``X-Request-ID``), and the logged 500 of an
    exception outside the taxonomy, quoting that id."""

    def __init__(self, app: ASGIApp) -> None:
        self.app = app

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        request_id = uuid.uuid4().hex
        started = False

        async def send_with_id(message: Message) -> None:
            nonlocal started
            if message["type"] == "http.response.start":
                started = True
                MutableHeaders(scope=message).append(REQUEST_ID_HEADER, request_id)
            await send(message)

        try:
            await self.app(scope, receive, send_with_id)
        except Exception as error:
            log.exception(
                "request %s: %s %s failed with an unexpected error", request_id, scope["method"], scope["path"]
            )
            if started:  # the answer is under way: nothing left to tell the client
                raise
            await _internal_error(error, request_id)(scope, receive, send_with_id)


def _internal_error(error: Exception, request_id: str) -> JSONResponse:
    body = {
        "detail": f"internal error (request {request_id}); the server log has the details",
        "error": type(error).__name__,
        "kind": ErrorKind.INTERNAL,
        "request_id": request_id,
    }
    return JSONResponse(body, status_code=OUTCOMES[ErrorKind.INTERNAL].http_status)
