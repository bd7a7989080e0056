"""Tool-side identification and tuning (issue #16 item 4; docs/identification.md): a back-and-forth experiment in
profile position through the motion guard, recorded by synchronous TPDOs, and the plant (inertia, viscous and
Coulomb friction, constant load) from it by least squares, for drives without auto-tuning (encoTRive, generic
CiA 402) and as a cross-check; then, on request, gains for a bandwidth verified by a step."""

from servostudio.services.identification.estimator import IdentificationFailed, Record, estimate
from servostudio.services.identification.experiment import (
    BadExperiment,
    ControllerLost,
    DriveFaulted,
    ExperimentOptions,
    LimitExceeded,
)
from servostudio.services.identification.service import IdentificationRequest, check, identify, start

__all__ = [
    "BadExperiment",
    "ControllerLost",
    "DriveFaulted",
    "ExperimentOptions",
    "IdentificationFailed",
    "IdentificationRequest",
    "LimitExceeded",
    "Record",
    "check",
    "estimate",
    "identify",
    "start",
]
