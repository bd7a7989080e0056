"""Background jobs (backup, restore of many drives): run in a thread, publish progress and the result as events.

A REST call that would take seconds starts a job and returns its id at once; the client follows it on
``/api/ws/events`` (``progress`` and ``job`` events) or polls ``GET /api/jobs/{id}``.  A client may cancel a
running job: the work gets a ``Cancellation``, stops at the next object or file boundary and returns what it did
so far; the job then ends ``cancelled`` with that result.
"""

from __future__ import annotations

import itertools
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field

from servostudio.services.bus.events import EventHub
from servostudio.services.cancel import Cancellation

Progress = Callable[[dict[str, object]], None]
KEEP_JOBS = 100


@dataclass
class Job:
    id: str
    operation: str
    state: str = "running"  # running | done | failed | cancelled
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
        self._numbers = itertools.count(1)
        self._lock = threading.Lock()

    def start(self, operation: str, work: Callable[[Progress, Cancellation], object]) -> Job:
        """Run ``work(progress, cancellation)`` in a thread; its return value (JSON-ready) becomes the job's
        result."""
        job = Job(id=f"job{next(self._numbers)}", operation=operation)
        with self._lock:
            self._jobs[job.id] = job
            for old in list(self._jobs)[:-KEEP_JOBS]:
                del self._jobs[old]

        def progress(event: dict[str, object]) -> None:
            self.events.publish({**event, "job": job.id})

        def run() -> None:
            try:
                job.result = work(progress, job.cancellation)
                job.state = "cancelled" if job.cancellation.requested else "done"
            except Exception as error:  # the job reports any failure to its client
                job.error = str(error)
                job.state = "cancelled" if job.cancellation.requested else "failed"
            job.finished = time.time()
            self.events.publish({"type": "job", **job.as_dict()})

        threading.Thread(target=run, name=job.id, daemon=True).start()
        return job

    def cancel(self, job_id: str) -> Job | None:
        """Ask a running job to stop (no effect on a finished one); None for an unknown id."""
        job = self._jobs.get(job_id)
        if job is not None and job.state == "running":
            job.cancellation.cancel()
        return job

    def get(self, job_id: str) -> Job | None:
        return self._jobs.get(job_id)

    def list(self) -> list[Job]:
        return list(self._jobs.values())
