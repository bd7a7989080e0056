"""HTTP status of the communication errors, in one place (installed by ``create_app``)."""

from __future__ import annotations

from fastapi import FastAPI, Request
from fastapi.responses import JSONResponse

from servostudio.drive.access import DriveAccessError, UnknownObjectError
from servostudio.drive.control import StateChangeError
from servostudio.drive.link import LinkDownError
from servostudio.drive.profiles import ProfileError
from servostudio.drive.sdo import SdoAbortError, SdoError, SdoLinkError, SdoTimeoutError
from servostudio.services.backup import BackupError, RestoreValidationError
from servostudio.services.bus import UnknownBusOrNode
from servostudio.services.motion import NoLiveClient
from servostudio.services.terminal import TerminalError
from servostudio.transport.spec import BusSpecError

#: most specific first
STATUS = [
    (UnknownBusOrNode, 404),
    (ProfileError, 404),
    (UnknownObjectError, 404),
    (RestoreValidationError, 422),
    (DriveAccessError, 422),
    (BusSpecError, 422),
    (TerminalError, 422),
    (SdoAbortError, 409),
    (StateChangeError, 409),
    (NoLiveClient, 409),
    (SdoTimeoutError, 504),
    (SdoLinkError, 503),
    (LinkDownError, 503),
    (SdoError, 502),
    (BackupError, 502),
    (ValueError, 422),  # any other refused input (NMT command, state name, …)
]


def register_error_handlers(app: FastAPI) -> None:
    for error_type, status in STATUS:
        app.add_exception_handler(error_type, _handler(status))


def _handler(status: int):
    async def handle(request: Request, error: Exception) -> JSONResponse:
        return JSONResponse(status_code=status, content={"detail": str(error), "error": type(error).__name__})

    return handle
