"""Liveness of the communication server."""

from fastapi import APIRouter
from pydantic import BaseModel

from servostudio import __version__

router = APIRouter(tags=["health"])


class Health(BaseModel):
    status: str
    version: str


@router.get("/health", response_model=Health)
def get_health() -> Health:
    return Health(status="ok", version=__version__)
