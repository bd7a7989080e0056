"""The speed loop of a drive in physical units (docs/what-if.md).

``GET …/speed-loop`` reads the gains and filters converted through the device profile; ``PUT …/speed-loop`` writes
the physical values given (the what-if page's "write these gains"), every value checked before anything is sent,
through the drive's gate.  The encoTRive reads as the gains it derives from its inertia setting and takes only
``inertia_setting_kgm2``; a drive without a speed-loop description answers 404.
"""

from __future__ import annotations

from typing import Any

from fastapi import APIRouter

from servostudio.api.deps import NodeDrive
from servostudio.api.errors import error_responses
from servostudio.api.routes.drives import DRIVE_ERRORS
from servostudio.api.routes.speed_loop_models import SpeedLoopChange, SpeedLoopModel, SpeedLoopWrite
from servostudio.api.security import Requires
from servostudio.errors import ErrorKind
from servostudio.services.frequency.speed_loop import read_speed_loop, write_speed_loop
from servostudio.services.users import Level

PATH = "/buses/{bus}/nodes/{node}/speed-loop"
router = APIRouter(tags=["frequency"])


@router.get(
    PATH,
    response_model=SpeedLoopModel,
    summary="The speed-loop gains and filters in physical units",
    responses=error_responses(*DRIVE_ERRORS),
    dependencies=[Requires(Level.OPERATOR)],
)
def get_speed_loop(drive: NodeDrive) -> dict[str, Any]:
    return read_speed_loop(drive)


@router.put(
    PATH,
    response_model=SpeedLoopWrite,
    summary="Write speed-loop gains and filters given in physical units (all checked before any write)",
    responses=error_responses(*DRIVE_ERRORS, ErrorKind.INVALID_INPUT),
    dependencies=[Requires(Level.EXPERT)],  # tuning is the Expert's (docs/security.md)
)
def put_speed_loop(body: SpeedLoopChange, drive: NodeDrive) -> dict[str, Any]:
    return write_speed_loop(drive, body.values())
