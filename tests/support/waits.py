"""Bounded waits: poll until something holds, and fail naming what did not happen (and the last value seen), so a
stuck drive, line or server gives a readable failure instead of a hanging suite. The bound only matters when the
wait fails, so it is generous: a loaded CI host must not turn a slow success into a failure."""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import TypeVar

T = TypeVar("T")


def wait_for(
    sample: Callable[[], T],
    condition: Callable[[T], bool],
    what: str,
    timeout: float = 10.0,
    period: float = 0.005,
    describe: Callable[[T], str] = lambda value: f"last value {value!r}",
) -> T:
    """Sample until ``condition(value)`` holds; that value. Fails with ``what`` and ``describe(last value)``."""
    deadline = time.monotonic() + timeout
    while True:
        value = sample()
        if condition(value):
            return value
        if time.monotonic() > deadline:
            raise AssertionError(f"{what} not seen within {timeout} s; {describe(value)}")
        time.sleep(period)


def eventually(condition: Callable[[], bool], timeout: float = 5.0, what: str = "the condition") -> float:
    """Wait until ``condition()`` holds; the seconds it took."""
    start = time.monotonic()
    wait_for(condition, bool, what, timeout, describe=lambda _: "it never held")
    return time.monotonic() - start
