"""The bookkeeping both transfer engines of a bus share around their own transport: the SDO engine's frames
(``drive/sdo.py``) and the PKW engine's requests over a PROFIBUS-DP line (``drive/profibus/engine.py``).

- Where a transfer's outcome goes: one future (`FutureCompletion`), or a slot of a `TransferBatch` — the reads or
  writes of many objects of one node with one future for all, its ``on_each`` callback and ``cancel()``.
- How long a caller waits for it: `settle`, bounded by a safety net (`SAFETY_WAIT`), since each engine ends every
  transfer itself but a stuck engine must not hang a request or a job for ever.
- In which order a node's waiting transfers are served: `NodeLanes`, what someone waits for interactively ahead of
  the bulk work of a backup or restore.
"""

from __future__ import annotations

import threading
from collections import deque
from collections.abc import Callable, Iterable
from concurrent.futures import Future
from typing import Any, Generic, Protocol, TypeVar

from servostudio.errors import Timeout

#: Safety net of every wait on a transfer: the engine ends each transfer itself, but a transfer may wait behind
#: many queued ones of its node, and a stuck reader thread must not hang a request or a job for ever.
SAFETY_WAIT = 120.0

#: What a transfer ends with before conversion: the bytes read, or None for a write. The transfer's direction
#: decides which, so the completions (shared by both directions) take either; the engines' methods say which.
Result = Any
R = TypeVar("R")
T = TypeVar("T")


class OutcomeOverdue(Timeout):
    """A transfer's outcome did not arrive within the safety bound of the wait (the bus reader is stuck)."""


def settle(future: Future[R], seconds: float = SAFETY_WAIT) -> R:
    """The result of a transfer's future, waiting at most ``seconds``; the one bounded wait of the product."""
    try:
        return future.result(seconds)
    except TimeoutError:
        raise OutcomeOverdue(f"no outcome of the transfer within {seconds:.0f} s; the bus reader is stuck") from None


class Completion(Protocol):
    """What an engine reports a transfer to: a single future or a slot of a batch. ``start`` when the transfer is
    about to be carried out (False: it was cancelled, its outcome is a ``CancelledError``), ``drive_silent`` when
    the drive stopped answering, ``done`` with the outcome (the result or the exception that ended it)."""

    def start(self, slot: int) -> bool: ...
    def drive_silent(self) -> None: ...
    def done(self, slot: int, outcome: Result | Exception) -> None: ...


def _converted(convert: Callable[..., object], *arguments: Any) -> object:
    """``convert(*arguments)``, or the error it raised: the caller gets any error of convert (ValueError: no value)."""
    try:
        return convert(*arguments)
    except Exception as error:  # noqa: BLE001 -- handed to the caller as the transfer's outcome
        return error


class FutureCompletion:
    """The outcome of one transfer goes to a future (after ``convert`` of a successful result)."""

    __slots__ = ("convert", "future")

    def __init__(self, convert: Callable[[Result], object] | None) -> None:
        self.future: Future[object] = Future()
        self.convert = convert

    def start(self, slot: int) -> bool:
        return self.future.set_running_or_notify_cancel()  # from now on cancel() refuses: the outcome is known

    def drive_silent(self) -> None:
        """Nothing more to drop: the transfer itself ends with its timeout."""

    def done(self, slot: int, outcome: Result | Exception) -> None:
        if self.future.done():  # cancelled before it was carried out
            return
        if not isinstance(outcome, Exception) and self.convert is not None:
            outcome = _converted(self.convert, outcome)
        if isinstance(outcome, Exception):
            self.future.set_exception(outcome)
        else:
            self.future.set_result(outcome)


class TransferBatch(Generic[R]):
    """Reads (or writes) of many objects of one node with one future for all: ``future`` gives a list, in request
    order, of each result — the bytes read or None for a write, passed through ``convert(position, result)`` when
    given — or the exception that ended that transfer.

    A backup reads hundreds of objects; one future per object would cost more client time than the frames.
    ``on_each(position, outcome)`` runs as each transfer ends (on the engine's thread: keep it short).
    ``cancel()`` drops the transfers not yet carried out; their outcome is a ``CancelledError``. A transfer that
    times out drops the rest the same way: a drive that stopped answering would otherwise cost a timeout per object.
    ``each`` is the seconds one transfer may take at most: `outcomes` waits the safety net plus all of them.
    """

    def __init__(
        self,
        count: int,
        convert: Callable[[int, Result], R] | None = None,
        on_each: Callable[[int, R | Exception], None] | None = None,
        each: float = 0.0,
    ) -> None:
        self.future: Future[list[R | Exception]] = Future()
        self.future.set_running_or_notify_cancel()
        self.patience = SAFETY_WAIT + count * each
        self._outcomes: list[Any] = [None] * count  # every slot is filled before the future completes
        self._left = count
        self._convert = convert
        self._on_each = on_each
        self._cancelled = False
        self._lock = threading.Lock()
        if count == 0:
            self.future.set_result([])

    def outcomes(self) -> list[R | Exception]:
        """Wait for every transfer of the batch (bounded by ``patience``) and give their outcomes."""
        return settle(self.future, self.patience)

    def cancel(self) -> None:
        self._cancelled = True

    def start(self, slot: int) -> bool:
        return not self._cancelled

    def drive_silent(self) -> None:
        """A transfer timed out: the drive stopped answering, the transfers still queued are dropped."""
        self._cancelled = True

    def done(self, slot: int, outcome: Result | Exception) -> None:
        if not isinstance(outcome, Exception) and self._convert is not None:
            outcome = _converted(self._convert, slot, outcome)
        with self._lock:
            self._outcomes[slot] = outcome
            self._left -= 1
            last = self._left == 0
        try:
            if self._on_each is not None:
                self._on_each(slot, outcome)
        finally:  # a failing callback must not leave the caller waiting forever
            if last:
                self.future.set_result(self._outcomes)


class NodeLanes(Generic[T]):
    """A node's waiting transfers in two lanes: what someone waits for interactively (a REST call, the terminal)
    goes ahead of bulk work (the batches of a backup or a restore), each lane in the order it was queued."""

    __slots__ = ("bulk", "interactive")

    def __init__(self) -> None:
        self.interactive: deque[T] = deque()
        self.bulk: deque[T] = deque()

    def __bool__(self) -> bool:
        return bool(self.interactive or self.bulk)

    def add(self, transfers: Iterable[T], bulk: bool) -> None:
        (self.bulk if bulk else self.interactive).extend(transfers)

    def next(self) -> T | None:
        lane = self.interactive or self.bulk
        return lane.popleft() if lane else None

    def drain(self) -> list[T]:
        """Every waiting transfer, taken out of the lanes (the link is gone)."""
        waiting = [*self.interactive, *self.bulk]
        self.interactive.clear()
        self.bulk.clear()
        return waiting
