"""Sequence mode of the XtrapulsPac (docs/sequences.md): SEQUENCE.TXT checked and shown with its chaining graph,
the drive's sequence memory read and written, programs started and stopped through the motion guard, and a live
monitor with the timeline of the executed sequences."""

from servostudio.services.sequences.files import OFFLINE, check, graph, keyword_catalog, parse, show
from servostudio.services.sequences.graph import ChainingGraph, chaining_graph
from servostudio.services.sequences.memory import (
    DownloadResult,
    DriveLimits,
    NoSequences,
    ProcedureFailed,
    SequenceTransferError,
    download,
    limits,
    reload,
    store_to_flash,
    upload,
    validate,
)
from servostudio.services.sequences.monitor import SequenceMonitor, phase_name
from servostudio.services.sequences.run import parse_bits, set_conditional_input, set_sim_inputs, start, stop
from servostudio.services.sequences.service import NoMonitor, SequenceMonitors

__all__ = [
    "OFFLINE",
    "ChainingGraph",
    "DownloadResult",
    "DriveLimits",
    "NoMonitor",
    "NoSequences",
    "ProcedureFailed",
    "SequenceMonitor",
    "SequenceMonitors",
    "SequenceTransferError",
    "chaining_graph",
    "check",
    "download",
    "graph",
    "keyword_catalog",
    "limits",
    "parse",
    "parse_bits",
    "phase_name",
    "reload",
    "set_conditional_input",
    "set_sim_inputs",
    "show",
    "start",
    "stop",
    "store_to_flash",
    "upload",
    "validate",
]
