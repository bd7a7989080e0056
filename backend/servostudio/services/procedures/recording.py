"""One recording for a verification: the capture service's recorder, with one more try at reading it back (a busy
bus can time out the block upload; the recording stays in the drive and is read again), or synchronous TPDOs on a
drive without a recorder (the definition asks for them)."""

from __future__ import annotations

from collections.abc import Callable

from servostudio.drive.access import Drive
from servostudio.services.cancel import Cancellation
from servostudio.services.scope import Capture, CaptureDefinition, CapturePlan, CaptureRefused, DriveIdentity
from servostudio.services.scope.capture import build_capture
from servostudio.services.scope.recorder import UploadFailed
from servostudio.services.scope.service import check, record_once, session_of, stream_once
from servostudio.services.scope.stream_plan import StreamPlan

Report = Callable[[dict[str, object]], None]


def record(drive: Drive, definition: CaptureDefinition, report: Report) -> Capture:
    """Configure and arm the recorder (``report`` hears its stages: act on ``waiting``), and read the recording."""
    plan = check(drive, definition)
    identity = DriveIdentity(bus="", node=drive.node, device=drive.profile.device)
    if isinstance(plan, StreamPlan) and plan.source == "tpdo":
        return stream_once(drive, plan, identity, report, Cancellation(), None)
    if not isinstance(plan, CapturePlan):
        raise CaptureRefused(f"node {drive.node}: the verification records with the recorder or synchronous TPDOs")
    session = session_of(drive)
    session.configure(plan)
    try:
        return record_once(session, plan, identity, report, Cancellation())
    except UploadFailed:
        recording = session.upload(plan, _quiet, Cancellation())
        return build_capture(plan, recording.data, recording.trigger_record, identity)


def _quiet(event: dict[str, object]) -> None:
    """The second reading is not reported."""
