"""What every project router shares: the error answers of the project service and its dependencies."""

from __future__ import annotations

from collections.abc import Callable, Coroutine
from typing import Annotated, Any

from fastapi import Depends, Request, Response
from fastapi.responses import JSONResponse
from fastapi.routing import APIRoute

from servostudio.api.deps import User, current_user
from servostudio.services.projects import ProjectService, errors

_STATUS = {
    errors.ProjectNotFound: 404,
    errors.ProjectExists: 409,
    errors.ConflictError: 409,
    errors.InvalidName: 422,
    errors.ValidationError: 422,
    errors.ParameterRefused: 422,
    errors.ArchiveError: 422,
    errors.FileFormatError: 422,
    errors.DriveMismatch: 409,
    errors.DriveUnavailable: 503,
}


class ProjectRoute(APIRoute):
    """Answers a service refusal as ``{"detail": message, "error": kind}`` with the status of its kind, the same
    shape as the communication errors (``api/routes/errors.py``), without touching the app."""

    def get_route_handler(self) -> Callable[[Request], Coroutine[Any, Any, Response]]:
        handler = super().get_route_handler()

        async def answer(request: Request) -> Response:
            try:
                return await handler(request)
            except errors.ProjectError as error:
                status = next((code for kind, code in _STATUS.items() if isinstance(error, kind)), 400)
                return JSONResponse(status_code=status, content={"detail": str(error), "error": type(error).__name__})

        return answer


def project_service(request: Request) -> ProjectService:
    """One service per app, on the server's project store and dictionary library."""
    state = request.app.state
    if getattr(state, "project_service", None) is None:
        state.project_service = ProjectService(state.settings.projects_dir, state.eds_library)
    return state.project_service


Service = Annotated[ProjectService, Depends(project_service)]
Caller = Annotated[User, Depends(current_user)]
