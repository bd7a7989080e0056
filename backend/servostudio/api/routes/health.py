"""Liveness of the communication server."""

from fastapi import APIRouter
from pydantic import BaseModel

from servostudio import __version__
from servostudio.api.security import Anyone

router = APIRouter(tags=["health"])


class Health(BaseModel):
    status: str
    version: str


@router.get("/health", response_model=Health, dependencies=[Anyone])
def get_health() -> Health:
    return Health(status="ok", version=__version__)
