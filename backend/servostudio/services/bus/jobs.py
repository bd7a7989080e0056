"""Background jobs (backup, restore of many drives): run in a thread, publish progress and the result as events.

A REST call that would take seconds starts a job and returns its id at once; the client follows it on
``/api/ws/events`` (``progress`` and ``job`` events) or polls ``GET /api/jobs/{id}``.  A client may cancel a
running job: the work gets a ``Cancellation``, stops at the next object or file boundary and returns what it did
so far; the job then ends ``cancelled`` with that result.

A job's states: ``running``, then ``done``, ``partial`` (some of its units — the nodes of a backup — failed, the
others completed), ``failed`` (the work raised, or every unit failed) or ``cancelled``.  Work made of units returns
`UnitResults`, so "every node failed" is not reported as done.
"""

from __future__ import annotations

import contextvars
import logging
import secrets
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field

from servostudio.errors import NotFound, ServoStudioError
from servostudio.services.bus.events import EventHub
from servostudio.services.cancel import Cancellation

log = logging.getLogger(__name__)
Progress = Callable[[dict[str, object]], None]
KEEP_JOBS = 100


class UnknownJob(NotFound):
    """No job of that id (never started, or one of the oldest, forgotten)."""


@dataclass(frozen=True)
class UnitResults:
    """What work made of independent units returns: ``result`` (JSON-ready, one entry per unit) and, for each unit
    that failed, why (``failures``, e.g. ``"node 2: no SDO response…"``); ``units`` counts them all."""

    result: object
    units: int
    failures: tuple[str, ...] = ()

    @property
    def state(self) -> str:
        if not self.failures:
            return "done"
        return "failed" if len(self.failures) >= self.units else "partial"

    @property
    def error(self) -> str:
        """One line for the job's ``error``: how many units failed and the first reasons."""
        if not self.failures:
            return ""
        shown = "; ".join(self.failures[:3]) + ("; …" if len(self.failures) > 3 else "")
        return f"{len(self.failures)} of {self.units} failed: {shown}"


@dataclass
class Job:
    id: str
    operation: str
    state: str = "running"  # running | done | partial | failed | cancelled
    result: object = None
    error: str = ""
    started: float = field(default_factory=time.time)
    finished: float | None = None
    cancellation: Cancellation = field(default_factory=Cancellation, repr=False)

    def as_dict(self) -> dict[str, object]:
        return {
            "id": self.id,
            "operation": self.operation,
            "state": self.state,
            "result": self.result,
            "error": self.error or None,
            "started": self.started,
            "finished": self.finished,
        }


class JobRegistry:
    def __init__(self, events: EventHub) -> None:
        self.events = events
        self._jobs: dict[str, Job] = {}
        self._lock = threading.Lock()

    def start(self, operation: str, work: Callable[[Progress, Cancellation], object]) -> Job:
        """Run ``work(progress, cancellation)`` in a thread; its return value (JSON-ready) becomes the job's
        result."""
        job = Job(id=f"job-{secrets.token_hex(16)}", operation=operation)  # unguessable, unlike a counter
        with self._lock:
            self._jobs[job.id] = job
            for old in list(self._jobs)[:-KEEP_JOBS]:
                del self._jobs[old]

        # the job acts for whoever started it (the motion guard and the audit log read it from the context)
        starter = contextvars.copy_context()
        threading.Thread(target=starter.run, args=(self._run, job, work), name=job.id, daemon=True).start()
        return job

    def _run(self, job: Job, work: Callable[[Progress, Cancellation], object]) -> None:
        def progress(event: dict[str, object]) -> None:
            self.events.publish({**event, "job": job.id})

        try:
            _record(job, work(progress, job.cancellation))
        except Exception as error:  # the job reports any failure to its client; a bug is logged as well
            if not isinstance(error, ServoStudioError):
                log.exception("%s %s failed unexpectedly", job.operation, job.id)
            job.state, job.error = "failed", _reason(job, error)
        if job.cancellation.requested:
            job.state = "cancelled"
        job.finished = time.time()
        self.events.publish({"type": "job", **job.as_dict()})

    def cancel(self, job_id: str) -> Job:
        """Ask a running job to stop (no effect on a finished one)."""
        job = self.get(job_id)
        if job.state == "running":
            job.cancellation.cancel()
        return job

    def get(self, job_id: str) -> Job:
        try:
            return self._jobs[job_id]
        except KeyError:
            raise UnknownJob(f"no job {job_id!r}") from None

    def list(self) -> list[Job]:
        return list(self._jobs.values())


def _record(job: Job, outcome: object) -> None:
    """The job's result and state from what its work returned."""
    if isinstance(outcome, UnitResults):
        job.result, job.state, job.error = outcome.result, outcome.state, outcome.error
    else:
        job.result, job.state = outcome, "done"


def _reason(job: Job, error: Exception) -> str:
    """The error a client sees; the text of one outside the taxonomy (a bug, which may name server paths) stays in
    the log."""
    if isinstance(error, ServoStudioError):
        return str(error)
    return f"internal error in {job.operation} {job.id}; the server log has the details"
