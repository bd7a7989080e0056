"""Sequences (docs/sequences.md): SEQUENCE.TXT checked with its chaining graph, the project's SEQUENCE.TXT, the
drive's sequence memory (upload, download LOAD/MERGE, store, reload from flash), starting and stopping programs
(through the motion guard: the caller's live client must have armed the axis), the conditional input, and the live
monitor with its timeline.  Every route is one call of ``services.sequences``."""

from __future__ import annotations

from typing import Annotated, Any

from fastapi import APIRouter, Depends, Query
from starlette.requests import HTTPConnection

from servostudio.api.deps import Motion, NodeDrive, OpenBus, Projects
from servostudio.api.errors import error_responses
from servostudio.api.routes.drives import DRIVE_ERRORS
from servostudio.api.routes.sequence_models import (
    CatalogModel,
    CheckModel,
    DownloadModel,
    DownloadRequest,
    DriveSequencesModel,
    InputsModel,
    InputsRequest,
    MonitorModel,
    ProjectSequences,
    ProjectSequencesWrite,
    ReloadRequest,
    RunModel,
    SequenceText,
    StartRequest,
)
from servostudio.api.security import Requires
from servostudio.errors import ErrorKind
from servostudio.formats.sequence import LoadMode, format_sequence_table
from servostudio.services import sequences
from servostudio.services.sequences import SequenceMonitors
from servostudio.services.sequences import project as project_file
from servostudio.services.users import Level

router = APIRouter(tags=["sequences"], responses=error_responses(*DRIVE_ERRORS))
NODE = "/buses/{bus}/nodes/{node}/sequences"
AXIS = "/projects/{name}/axes/{axis}/sequences"


def monitors(connection: HTTPConnection) -> SequenceMonitors:
    found: SequenceMonitors = connection.app.state.sequences
    return found


Monitors = Annotated[SequenceMonitors, Depends(monitors)]


@router.get("/sequences/keywords", response_model=CatalogModel, dependencies=[Requires(Level.OPERATOR)])
def keywords() -> dict[str, object]:
    """Every type's keywords: 0x3611 sub, unit, allowed values, default (the editor's fields)."""
    return sequences.keyword_catalog()


@router.post("/sequences/check", response_model=CheckModel, dependencies=[Requires(Level.OPERATOR)])
def check(body: SequenceText) -> dict[str, object]:
    """The file reader's verdict (issues with line, keyword and allowed range) and, when valid, the sequences and
    the chaining graph; nothing is written anywhere."""
    return sequences.check(body.text, body.file)


@router.get(AXIS, response_model=ProjectSequences, dependencies=[Requires(Level.OPERATOR)])
def read_project(name: str, axis: str, service: Projects) -> dict[str, object]:
    text, revision = project_file.read_text(service, name, axis)
    return {"text": text, "revision": revision}


@router.put(
    AXIS,
    response_model=ProjectSequences,
    dependencies=[Requires(Level.EXPERT)],
    responses=error_responses(ErrorKind.TOO_LARGE),  # a SEQUENCE.TXT beyond the request size limit
)
def write_project(name: str, axis: str, body: ProjectSequencesWrite, service: Projects) -> dict[str, object]:
    """Checked by the file reader first: a file with an error is refused whole (422) and nothing is written."""
    revision = project_file.write_text(service, name, axis, body.text, body.revision)
    return {"text": body.text, "revision": revision}


@router.get(NODE, response_model=DriveSequencesModel, dependencies=[Requires(Level.OPERATOR)])
def upload(drive: NodeDrive) -> dict[str, object]:
    """The sequence memory as SEQUENCE.TXT, its sequences and graph against the drive's 0x3612 and 0x360F."""
    found = sequences.limits(drive)
    text = format_sequence_table(sequences.upload(drive))
    verdict = sequences.check(text, "SEQUENCE.TXT", found)
    return {**verdict, "text": text, "count": found.count, "types": [kind.name for kind in found.types]}


@router.put(
    NODE,
    response_model=DownloadModel,
    dependencies=[Requires(Level.MAINTENANCE)],
    responses=error_responses(ErrorKind.COMMUNICATION, ErrorKind.TOO_LARGE),
)
def download(drive: NodeDrive, body: DownloadRequest) -> dict[str, object]:
    """Validate the whole file against the drive, write it (LOAD or MERGE), verify, store if asked."""
    return sequences.download(drive, body.text, LoadMode(body.mode), body.store, body.file).as_dict()


@router.post(f"{NODE}/store", response_model=RunModel, dependencies=[Requires(Level.MAINTENANCE)])
def store(drive: NodeDrive) -> dict[str, object]:
    """``sseq``: the sequence memory into the drive's SEQUENCE.TXT."""
    sequences.store_to_flash(drive)
    return {"node": drive.node}


@router.post(f"{NODE}/reload", response_model=RunModel, dependencies=[Requires(Level.MAINTENANCE)])
def reload(drive: NodeDrive, body: ReloadRequest) -> dict[str, object]:
    """``lseq`` / ``mseq``: the drive's SEQUENCE.TXT into its sequence memory."""
    sequences.reload(drive, LoadMode(body.mode))
    return {"node": drive.node}


@router.post(f"{NODE}/start", response_model=RunModel, dependencies=[Requires(Level.MAINTENANCE)])
def start(connection: OpenBus, drive: NodeDrive, body: StartRequest, motion: Motion) -> dict[str, Any]:
    """Sequence mode, enable, start ``sequence``: the caller's live client must be the axis's armed controller."""
    return sequences.start(motion, connection.id, drive, body.sequence)


@router.post(f"{NODE}/stop", response_model=RunModel, dependencies=[Requires(Level.MAINTENANCE)])
def stop(drive: NodeDrive) -> dict[str, object]:
    """Control word bit 5: the program brakes and ends (the armed controller's, as every control word of an
    enabled axis)."""
    return sequences.stop(drive)


@router.put(f"{NODE}/inputs", response_model=InputsModel, dependencies=[Requires(Level.MAINTENANCE)])
def inputs(drive: NodeDrive, body: InputsRequest) -> dict[str, object]:
    """The conditional input 0x3601,3 and, on the simulator, the physical inputs IN1..IN5."""
    sim = sequences.set_sim_inputs(drive, body.sim) if body.sim is not None else None
    if body.conditional is not None:
        sequences.set_conditional_input(drive, body.conditional)
    return {"conditional": int(drive.read("sequence_conditional_input").raw) & 0xFFFF, "sim": sim}


@router.post(f"{NODE}/monitor", response_model=MonitorModel, dependencies=[Requires(Level.MAINTENANCE)])
def start_monitor(connection: OpenBus, drive: NodeDrive, found: Monitors, fresh: bool = False) -> dict[str, object]:
    """Map TPDO 4 (0x3605, 0x3601,2, 0x3602,1, 0x3602,3, event-driven) and watch it; ``fresh`` empties the
    timeline."""
    return found.start(connection, drive, fresh).snapshot()


@router.get(f"{NODE}/monitor", response_model=MonitorModel, dependencies=[Requires(Level.OPERATOR)])
def read_monitor(
    connection: OpenBus, node: int, found: Monitors, since: Annotated[int, Query(ge=0)] = 0
) -> dict[str, object]:
    """The state now and the timeline from sample ``since`` on."""
    return found.get((connection.id, node)).snapshot(since)


@router.delete(f"{NODE}/monitor", status_code=204, dependencies=[Requires(Level.MAINTENANCE)])
def stop_monitor(connection: OpenBus, node: int, found: Monitors) -> None:
    found.stop((connection.id, node))
