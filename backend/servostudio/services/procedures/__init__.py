"""The procedure service (issue #13; docs/commissioning.md): auto-phasing, motor phasing, the current-loop and
current-limit calculations and auto-tuning, one implementation for every signature-started procedure — preconditions
read from the drive before the start, start, status polling with progress events, abort, timeouts, the failure turned
into a reason, results before → after, verification, results kept in the project."""

from servostudio.services.procedures.options import BadOptions
from servostudio.services.procedures.preconditions import Precondition, PreconditionsUnmet, preconditions
from servostudio.services.procedures.run import ControllerGone, ProcedureFailed, ProcedureTimeout
from servostudio.services.procedures.service import (
    ProcedureRequest,
    ProcedureService,
    UnknownProcedure,
    describe,
    description_of,
)
from servostudio.services.procedures.store import ResultStore
from servostudio.services.procedures.undo import BadUndo

__all__ = [
    "BadOptions",
    "BadUndo",
    "ControllerGone",
    "Precondition",
    "PreconditionsUnmet",
    "ProcedureFailed",
    "ProcedureRequest",
    "ProcedureService",
    "ProcedureTimeout",
    "ResultStore",
    "UnknownProcedure",
    "describe",
    "description_of",
    "preconditions",
]
