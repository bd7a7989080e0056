"""I/O configuration (docs/io.md): the logic inputs' functions and polarity, the outputs, analog scaling, encoder
emulation and the CANopen I/O extension of one drive, its live I/O state and the fail-safe check of its limit
switches; on a simulated drive also its test bench inputs.  Every route is one call of ``services.io``; a change
goes whole through the motion guard."""

from __future__ import annotations

from fastapi import APIRouter

from servostudio.api.deps import NodeDrive, OpenBus
from servostudio.api.errors import error_responses
from servostudio.api.routes.drives import DRIVE_ERRORS
from servostudio.api.routes.io_models import IoChangeRequest, IoLiveModel, IoModel, IoSimInputsRequest
from servostudio.api.security import Requires
from servostudio.services import io
from servostudio.services.users import Level

router = APIRouter(tags=["io"], responses=error_responses(*DRIVE_ERRORS))
NODE = "/buses/{bus}/nodes/{node}/io"


@router.get(NODE, response_model=IoModel, dependencies=[Requires(Level.OPERATOR)])
def read(connection: OpenBus, drive: NodeDrive) -> dict[str, object]:
    """Every input and output with its function and polarity, the settings, the live state and the findings."""
    return io.read(drive, connection.simulation is not None)


@router.get(f"{NODE}/state", response_model=IoLiveModel, dependencies=[Requires(Level.OPERATOR)])
def live(connection: OpenBus, drive: NodeDrive) -> dict[str, object]:
    """The live I/O alone, cheap enough to poll."""
    return io.state(drive, connection.simulation is not None)


@router.put(NODE, response_model=IoModel, dependencies=[Requires(Level.EXPERT)])
def change(connection: OpenBus, drive: NodeDrive, body: IoChangeRequest) -> dict[str, object]:
    """Check the whole change (422 and nothing written on any problem), then write it through the motion guard."""
    request = io.IoChange(
        inputs=[io.InputChange(row.name, row.function, row.inverted) for row in body.inputs],
        outputs=[io.OutputChange(row.name, row.function, row.inverted) for row in body.outputs],
        settings=body.settings,
    )
    return io.apply(drive, request, connection.simulation is not None)


@router.put(f"{NODE}/sim-inputs", response_model=IoLiveModel, dependencies=[Requires(Level.MAINTENANCE)])
def sim_inputs(connection: OpenBus, drive: NodeDrive, body: IoSimInputsRequest) -> dict[str, object]:
    """Simulator only: the test bench's inputs (0x5F00); 409 on a real drive."""
    return io.set_sim_inputs(drive, body.value, connection.simulation is not None)
