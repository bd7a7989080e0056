"""What the jobs running on one bus hold of it: the nodes whose PDOs and recorder they borrow, and the bus's SYNC.

A scope capture, a roll, a multi-axis capture, a frequency response and an identification each borrow a drive's
PDOs (the last RPDO, TPDOs) and its recorder for their run and write them back at the end; two at once on one node
would overwrite each other's mappings and both be wrong. CiA 301 has one SYNC producer per network: with two,
every drive answers both, and no job's samples are one per period any more. So every such job starts through the
bus's one `BusClaims` (``BusConnection.claims``): refused with 409 naming the job that holds the node or the SYNC,
else started and holding them until it ends (a claim lasts while its job is running: nothing to release).
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterable

from servostudio.errors import Conflict
from servostudio.services.bus.jobs import Job


class Claimed(Conflict):
    """A node or the bus's SYNC is held by a running job."""


class BusClaims:
    """The nodes and the SYNC of one bus that running jobs hold."""

    def __init__(self, bus: str) -> None:
        self.bus = bus
        self._nodes: dict[int, Job] = {}
        self._sync: Job | None = None
        self._lock = threading.Lock()

    def start(self, nodes: Iterable[int], start: Callable[[], Job], sync: bool = False) -> Job:
        """Start a job (``start``) that holds ``nodes`` and, with ``sync``, the bus's SYNC — refused (`Claimed`)
        when a running job holds one of them; the check and the start are one step, so two requests cannot both
        pass."""
        held = tuple(dict.fromkeys(nodes))
        with self._lock:
            for node in held:
                self._refuse_node(node)
            if sync:
                self._refuse_sync()
            job = start()
            self._nodes.update(dict.fromkeys(held, job))
            if sync:
                self._sync = job
        return job

    def holder(self, node: int) -> Job | None:
        """The running job that holds the node, if any."""
        job = self._nodes.get(node)
        return job if job is not None and job.state == "running" else None

    def sync_holder(self) -> Job | None:
        """The running job that sends the bus's SYNC, if any."""
        job = self._sync
        return job if job is not None and job.state == "running" else None

    def _refuse_node(self, node: int) -> None:
        job = self.holder(node)
        if job is not None:
            raise Claimed(f"node {node}: {_named(job)} is running on it (its PDOs and recorder are borrowed); "
                          "stop it first")  # fmt: skip

    def _refuse_sync(self) -> None:
        job = self.sync_holder()
        if job is not None:
            raise Claimed(f"bus {self.bus}: {_named(job)} sends the SYNC (one SYNC producer per bus); stop it "
                          "first, or capture these channels with it")  # fmt: skip


def _named(job: Job) -> str:
    """A job as a refusal names it: what it does and its id."""
    return f"{job.operation} {job.id}"
