"""Dialog terminal (manual §2.7): read or write any object on up to 4 axes at once, with continuous monitoring.

A ``Watch`` is the list of objects the terminal shows; ``sample`` reads them all in one go (reads of different
nodes run in parallel, reads of one node back to back) and returns one row per object, each with its value or
the error that object gave, so a missing drive does not blank the other axes.
"""

from __future__ import annotations

from concurrent.futures import Future, wait
from dataclasses import dataclass

from servostudio.drive.access import Drive
from servostudio.errors import InvalidInput, ServoStudioError
from servostudio.services.bus.connections import ConnectionManager

MAX_AXES = 4
MAX_ITEMS = 32
MIN_PERIOD = 0.05


class TerminalError(InvalidInput):
    """A watch list the terminal refuses (too many axes, unknown bus/object)."""


@dataclass(frozen=True)
class WatchItem:
    bus: str
    node: int
    object: str


@dataclass(frozen=True)
class Watch:
    items: tuple[WatchItem, ...]
    period: float = 0.2

    def __post_init__(self) -> None:
        axes = {(item.bus, item.node) for item in self.items}
        if len(axes) > MAX_AXES:
            raise TerminalError(f"the terminal works on up to {MAX_AXES} axes at once, got {len(axes)}")
        if len(self.items) > MAX_ITEMS:
            raise TerminalError(f"at most {MAX_ITEMS} objects can be watched, got {len(self.items)}")
        if self.period < MIN_PERIOD:
            raise TerminalError(f"monitoring period must be at least {MIN_PERIOD * 1000:.0f} ms")


def sample(manager: ConnectionManager, watch: Watch, timeout: float = 2.0) -> list[dict[str, object]]:
    """Read every watched object once, all within ``timeout`` seconds; one row per item with ``value`` or
    ``error``."""
    pending: list[tuple[WatchItem, Future | None, str]] = []
    for item in watch.items:
        try:
            drive = manager.get(item.bus).drive(item.node)
            pending.append((item, drive.submit_read(drive.variable(item.object)), ""))
        except ServoStudioError as error:
            pending.append((item, None, str(error)))
    _wait_for([future for _, future, _ in pending], timeout)
    return [
        {"bus": item.bus, "node": item.node, "object": item.object, **_outcome(future, refusal, timeout)}
        for item, future, refusal in pending
    ]


def read_objects(drive: Drive, keys: list[str], timeout: float = 5.0) -> list[dict[str, object]]:
    """Read many objects of one node, queued back to back, all within ``timeout`` seconds; one row per key with
    ``value`` or ``error``."""
    pending: list[tuple[str, Future | None, str]] = []
    for key in keys:
        try:
            pending.append((key, drive.submit_read(drive.variable(key)), ""))
        except ServoStudioError as error:
            pending.append((key, None, str(error)))
    _wait_for([future for _, future, _ in pending], timeout)
    return [
        {"object": key, "value": None, "error": None, **_outcome(future, refusal, timeout)}
        for key, future, refusal in pending
    ]


def _wait_for(futures: list[Future | None], timeout: float) -> None:
    """One bounded wait for every read (not one timeout per read: 32 silent objects must not take 32 timeouts)."""
    wait([future for future in futures if future is not None], timeout)


def _outcome(future: Future | None, refusal: str, waited: float) -> dict[str, object]:
    """A read's ``value``, or its ``error``: refused before it was sent, failed, or no answer in time."""
    if future is None:
        return {"error": refusal}
    if not future.done():
        return {"error": f"no answer within {waited:g} s"}
    try:
        return {"value": future.result(0).as_dict()}
    except (ServoStudioError, ValueError) as failure:
        return {"error": str(failure)}
