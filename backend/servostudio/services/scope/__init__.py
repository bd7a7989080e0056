"""The oscilloscope's capture service (issue #12; docs/scope.md §4–6): capture definitions checked against a drive,
the in-drive recorder driven over SDO, captures in physical units with time 0 at the trigger, presets, the capture
file format (CSV + JSON sidecar) and captures saved in the project under their axis, HTML export."""

from servostudio.services.scope.capture import Capture, ChannelInfo, DriveIdentity
from servostudio.services.scope.capturefile import CaptureFileError, capture_csv, capture_sidecar, parse_capture
from servostudio.services.scope.definition import CaptureDefinition, DefinitionError, Trigger, parse_trigger
from servostudio.services.scope.export import capture_html
from servostudio.services.scope.plan import CapturePlan, CaptureRefused, NoRecorder
from servostudio.services.scope.presets import PRESETS, Preset, preset, presets_for
from servostudio.services.scope.recorder import NoTrigger, UploadFailed
from servostudio.services.scope.service import ScopeService, capture, check, identity_of
from servostudio.services.scope.store import CaptureStore, SavedCapture

__all__ = [
    "PRESETS",
    "Capture",
    "CaptureDefinition",
    "CaptureFileError",
    "CapturePlan",
    "CaptureRefused",
    "CaptureStore",
    "ChannelInfo",
    "DefinitionError",
    "DriveIdentity",
    "NoRecorder",
    "NoTrigger",
    "Preset",
    "SavedCapture",
    "ScopeService",
    "Trigger",
    "UploadFailed",
    "capture",
    "capture_csv",
    "capture_html",
    "capture_sidecar",
    "check",
    "identity_of",
    "parse_capture",
    "parse_trigger",
    "preset",
    "presets_for",
]
