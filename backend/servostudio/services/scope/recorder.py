"""The drive's recorder driven over SDO: configure, arm, force, stop, watch the status, upload the recording.

The steps are those of docs/scope.md §1. The upload reads the whole recording (the DOMAIN 0x5801) in one block
SDO upload — segmented where the drive refuses blocks (``drive.sdo``) — reporting its progress after every block
and stoppable between two blocks; the drive takes the recording's bytes when the upload starts, and the recording
counter read before and after proves they are the recording the capture waited for.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

from servostudio.drive.access import Drive
from servostudio.drive.profiles.recorder import RecorderDescription
from servostudio.drive.sdo import LARGE_SAFETY_WAIT, SdoStopped, settle
from servostudio.errors import CommunicationError, Conflict, ServoStudioError, Timeout
from servostudio.od.datatypes import DataType
from servostudio.od.model import Variable
from servostudio.services.cancel import Cancellation, Cancelled
from servostudio.services.scope.plan import CapturePlan, RecorderLimits

#: how often the status is read while waiting (an SDO read costs the bus about 0.2 ms)
POLL_SECONDS = 0.02

#: what a progress callback hears: ``{"stage": "waiting"}``, ``{"stage": "uploading", "done": …, "total": …}``
Report = Callable[[dict[str, object]], None]


class RecorderLayoutMismatch(Conflict):
    """The drive describes another record layout than the one configured (a drive that changed meanwhile)."""


class UploadFailed(CommunicationError):
    """The recording could not be read completely; nothing of it was kept."""


class NoTrigger(Timeout):
    """The recording did not complete in the time given; the recorder was stopped."""


@dataclass(frozen=True)
class Recording:
    """The bytes of one complete recording and where its trigger record is."""

    data: bytes
    trigger_record: int
    records: int
    counter: int


class RecorderSession:
    """One drive's recorder through its dictionary and the profile's description."""

    def __init__(self, drive: Drive, recorder: RecorderDescription) -> None:
        self.drive = drive
        self.recorder = recorder

    # -- single objects ------------------------------------------------------------------------------------------
    def read(self, name: str) -> int:
        value = self.drive.read(self.recorder.address(name)).raw
        assert isinstance(value, int)
        return value

    def write(self, name: str, value: int) -> None:
        self.drive.write(self.recorder.address(name), value)

    def limits(self) -> RecorderLimits:
        return RecorderLimits(capacity=self.read("capacity"), base_period_ns=self.read("base_period"))

    def status(self) -> str:
        return self.recorder.status_name(self.read("status"))

    # -- commands ------------------------------------------------------------------------------------------------
    def command(self, name: str) -> None:
        self.write("control", self.recorder.commands[name])

    def configure(self, plan: CapturePlan) -> None:
        """Stop, then write every setting of the plan (channels beyond the plan's off), then check the record layout
        the drive reports against the plan's."""
        self.command("stop")
        writes = [*self._channel_writes(plan), *self._setting_writes(plan)]
        batch = self.drive.submit_write_all(writes)
        failed = next((outcome for outcome in batch.outcomes() if isinstance(outcome, Exception)), None)
        if failed is not None:
            raise failed
        self._check_layout(plan)

    def _channel_writes(self, plan: CapturePlan) -> list[tuple[Variable, object]]:
        pointers = [channel.pointer for channel in plan.channels]
        pointers += [0] * (self.recorder.channels - len(pointers))
        index = self.recorder.channel_sources
        return [(self.drive.variable((index, n)), pointer) for n, pointer in enumerate(pointers, 1)]

    def _setting_writes(self, plan: CapturePlan) -> list[tuple[Variable, object]]:
        settings = {
            "depth": plan.depth,
            "multiplier": plan.multiplier,
            "pre_trigger": plan.pre_trigger,
            "trigger_source": plan.trigger_source,
            "trigger_mode": plan.trigger_mode,
            "rearm": plan.rearm,
            "auto_timeout": plan.auto_timeout_ms,
            "trigger_level": plan.trigger_level,
            "trigger_edge": plan.trigger_edge,
        }
        return [(self.drive.variable(self.recorder.address(name)), value) for name, value in settings.items()]

    def _check_layout(self, plan: CapturePlan) -> None:
        index = self.recorder.channel_types
        types = [self.drive.read((index, n)).raw for n in range(1, len(plan.channels) + 1)]
        expected = [int(DataType(channel.variable.data_type)) for channel in plan.channels]
        size = self.read("record_size")
        if types != expected or size != plan.record_size:
            raise RecorderLayoutMismatch(
                f"node {self.drive.node}: the recorder reports channel types {types} and {size}-byte records; "
                f"the capture needs {expected} and {plan.record_size} bytes"
            )

    # -- waiting -------------------------------------------------------------------------------------------------
    def wait_recording(
        self, plan: CapturePlan, report: Report, cancellation: Cancellation, counter_before: int
    ) -> None:
        """Until a new recording is complete: status done (single) or the counter moved on (normal, auto). Each
        status change is reported; a cancel or the timeout stops the recorder."""
        deadline = None if plan.definition.timeout_s is None else time.monotonic() + plan.definition.timeout_s
        shown = ""
        while True:
            status = self.status()
            if status != shown:
                report({"stage": status})
                shown = status
            if status == "idle":
                raise Cancelled("the recorder was stopped before the recording completed")
            if self._complete(plan, status, counter_before):
                return
            self._check_wait(cancellation, deadline, status, plan)
            time.sleep(POLL_SECONDS)

    def _complete(self, plan: CapturePlan, status: str, counter_before: int) -> bool:
        """Single mode ends in status done; normal and auto re-arm at once, so only the counter tells."""
        if plan.definition.mode == "single":
            return status == "done"
        return self.read("counter") != counter_before

    def _check_wait(self, cancellation: Cancellation, deadline: float | None, status: str, plan: CapturePlan) -> None:
        if cancellation.requested:
            self.command("stop")
            raise Cancelled("capture stopped before the recording completed")
        if deadline is not None and time.monotonic() > deadline:
            self.command("stop")
            raise NoTrigger(
                f"node {self.drive.node}: no complete recording within {plan.definition.timeout_s:g} s "
                f"(recorder {status}); the recorder was stopped"
            )

    # -- upload --------------------------------------------------------------------------------------------------
    def upload(self, plan: CapturePlan, report: Report, cancellation: Cancellation) -> Recording:
        """The last complete recording; any failure leaves nothing behind but the error."""
        try:
            return self._upload(plan, report, cancellation)
        except (Cancelled, UploadFailed):
            raise
        except ServoStudioError as error:
            raise UploadFailed(
                f"node {self.drive.node}: the upload of the recording failed ({error}); nothing was kept, "
                "the recording stays in the drive and the recorder can be armed again"
            ) from error

    def _upload(self, plan: CapturePlan, report: Report, cancellation: Cancellation) -> Recording:
        counter, records, trigger = self.read("counter"), self.read("records"), self.read("trigger_record")
        total = records * plan.record_size
        report({"stage": "uploading", "done": 0, "total": total})
        index, sub = self.recorder.address("buffer")
        future = self.drive.engine.upload_block(
            self.drive.node,
            index,
            sub,
            progress=lambda done, _: report({"stage": "uploading", "done": min(done, total), "total": total}),
            stop=lambda: cancellation.requested,
        )
        try:
            data = settle(future, LARGE_SAFETY_WAIT)
        except SdoStopped:
            raise Cancelled("capture stopped during the upload; nothing was kept") from None
        if len(data) != total or self.read("counter") != counter:
            raise UploadFailed(
                f"node {self.drive.node}: the drive changed the recording during the upload "
                f"({len(data)} of {total} bytes); nothing was kept"
            )
        report({"stage": "uploading", "done": total, "total": total})
        return Recording(data, trigger, records, counter)
