"""The master side of the PKW mailbox: one request at a time, repeated in every PPO write until its reply comes.

Rules (TTA-PRO Profibus Communication Profile, Chapter 1 §3.2-3.4, L346-395): the master repeats an instruction
until the matching reply arrives; the slave presents a reply until the next instruction; a procedure answers
PWE 0 while it runs (keep the request on the bus, do not restart it), then 1 (done) or 2 (error); the same
procedure twice in a row needs a PKE = 0 instruction in between.

The channel sends AK 0 after *every* transaction and waits until the slave shows AK 0 before the next request.
That one rule covers the procedure repeat and makes a stale reply impossible to take for the next one (two reads
of the same PNU in a row look alike otherwise). The channel has no clock: the caller times out.
"""

from __future__ import annotations

import enum

from servostudio.drive.profibus.pkw import IDLE, PkwMessage, Reply, from_pwe
from servostudio.drive.profibus.pkw_errors import PkwInhibited, PkwRefused, ProcedureFailed

PROCEDURE_RUNNING = 0
PROCEDURE_FAILED = 2
"""A procedure's PWE: 0 running, 1 done, 2 error."""
ANSWERS = frozenset({Reply.VALUE, Reply.VALUE_DOUBLE, Reply.REFUSED, Reply.INHIBITED})


class _Phase(enum.Enum):
    SEPARATING = "waiting for the slave to show AK 0"
    READY = "ready for a request"
    PENDING = "waiting for the reply"


class PkwChannel:
    """Call `output()` for every PPO write and `receive(reply)` with every PPO read."""

    def __init__(self) -> None:
        self._phase = _Phase.SEPARATING  # the slave may still present a reply from before we came
        self._request: PkwMessage | None = None
        self._procedure = False

    @property
    def busy(self) -> bool:
        """A request is queued or waiting for its reply."""
        return self._request is not None

    def submit(self, request: PkwMessage, procedure: bool = False) -> None:
        if self.busy:
            raise RuntimeError("the PKW channel carries one request at a time")
        self._request = request
        self._procedure = procedure
        if self._phase is _Phase.READY:
            self._phase = _Phase.PENDING

    def abandon(self) -> None:
        """Give up the pending request (its reply did not come in time, or the link was lost): AK 0 goes out
        next, and the next request waits until the slave shows AK 0, so a late reply cannot answer it."""
        self._request = None
        self._phase = _Phase.SEPARATING

    def output(self) -> PkwMessage:
        """The PKW module of the next PPO write."""
        if self._phase is _Phase.PENDING and self._request is not None:
            return self._request
        return IDLE

    def receive(self, reply: PkwMessage) -> PkwMessage | None:
        """The reply that completes the pending request, else None (keep calling)."""
        if self._phase is _Phase.SEPARATING:
            if reply.ak == Reply.NONE:
                self._phase = _Phase.PENDING if self._request is not None else _Phase.READY
            return None
        if self._phase is not _Phase.PENDING or not self._answers(reply):
            return None
        self._request = None
        self._phase = _Phase.SEPARATING
        return reply

    def _answers(self, reply: PkwMessage) -> bool:
        request = self._request
        if request is None or reply.pnu != request.pnu or reply.ak not in ANSWERS:
            return False
        running = self._procedure and reply.ak == Reply.VALUE and reply.value == PROCEDURE_RUNNING
        return not running


def reply_value(request: PkwMessage, reply: PkwMessage, *, double: bool, signed: bool, procedure: bool = False) -> int:
    """The parameter value of a completing reply; PkwError subclasses for a refusal or a failed procedure."""
    if reply.ak == Reply.REFUSED:
        raise PkwRefused(request.pnu, request.index, reply.value)
    if reply.ak == Reply.INHIBITED:
        raise PkwInhibited(request.pnu, request.index)
    if procedure and reply.value == PROCEDURE_FAILED:
        raise ProcedureFailed(request.pnu, request.index)
    return from_pwe(reply.value, double, signed)
