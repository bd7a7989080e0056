"""A live drive as a compare column: every object of interest read at once, then served from memory.

``compare`` asks its sources one object at a time; a drive answering each question with its own blocking round trip
would make a 400-object compare take 400 round trips back to back. ``DriveValues`` instead queues every read at
once (``Drive.submit_read_all``) — the SDO engine then keeps the drive busy back to back — and waits for the answers
afterwards. An object the drive refuses (SDO abort) or answers with bytes that are no value of its type has no
value and the reason is kept; a drive that stops answering fails the whole read (a compare against half a drive
would be misleading).
"""

from __future__ import annotations

from collections.abc import Iterable

from servostudio.drive.access import DEFAULT_WAIT, Drive
from servostudio.drive.sdo import SdoAbortError
from servostudio.od import Variable
from servostudio.services.projects.parameter_values import Value

Key = tuple[int, int]


class DriveValues:
    """The values one drive holds for a set of objects (the ``ParameterSource`` protocol)."""

    def __init__(self, drive: Drive, variables: Iterable[Variable]) -> None:
        self.drive = drive
        self.values: dict[Key, Value] = {}
        self.refused: dict[Key, str] = {}  # object -> the drive's reason (SDO abort)
        readable = [var for var in variables if var.access.readable]
        outcomes = drive.submit_read_all(readable).future.result(DEFAULT_WAIT)
        for variable, outcome in zip(readable, outcomes, strict=True):
            if isinstance(outcome, SdoAbortError):
                self.refused[variable.key] = outcome.reason
            elif isinstance(outcome, ValueError):
                self.refused[variable.key] = str(outcome)
            elif isinstance(outcome, Exception):  # no answer: the first such read ended the batch
                raise outcome
            else:
                raw = outcome.raw
                self.values[variable.key] = raw.rstrip("\0") if isinstance(raw, str) else raw

    def read(self, index: int, sub: int) -> Value | None:
        return self.values.get((index, sub))
