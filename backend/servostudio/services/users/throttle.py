"""Login rate limits: guessing passwords from a page or a script costs hours, not seconds.

At most 5 failed logins per user name and 20 per client address within 15 minutes; past that, every login for
that name or from that address is refused (HTTP 429, kind ``rate_limited``) until the oldest failure leaves the
window, even with the right password. A successful login clears its user name's failures.
"""

from __future__ import annotations

import threading
import time
from collections import defaultdict, deque
from collections.abc import Callable

from servostudio.errors import RateLimited

FAILURES_PER_USER = 5
FAILURES_PER_ADDRESS = 20
WINDOW_SECONDS = 15 * 60


class TooManyLogins(RateLimited):
    """Refused without checking the password: too many recent failures for this name or address."""


class LoginThrottle:
    def __init__(self, clock: Callable[[], float] = time.monotonic) -> None:
        self.clock = clock
        self._failures: defaultdict[str, deque[float]] = defaultdict(deque)
        self._lock = threading.Lock()

    def check(self, name: str, address: str) -> None:
        for key, limit in ((f"user:{name}", FAILURES_PER_USER), (f"address:{address}", FAILURES_PER_ADDRESS)):
            wait = self._wait(key, limit)
            if wait > 0:
                raise TooManyLogins(f"too many failed logins ({key}); try again in {wait:.0f} s", retry_after=wait)

    def _wait(self, key: str, limit: int) -> float:
        """Seconds until ``key`` may try again (0: now)."""
        with self._lock:
            recent = self._recent(key)
            return WINDOW_SECONDS - (self.clock() - recent[0]) if len(recent) >= limit else 0.0

    def _recent(self, key: str) -> deque[float]:
        failures = self._failures[key]
        while failures and self.clock() - failures[0] >= WINDOW_SECONDS:
            failures.popleft()
        return failures

    def failed(self, name: str, address: str) -> None:
        with self._lock:
            for key in (f"user:{name}", f"address:{address}"):
                self._recent(key).append(self.clock())

    def succeeded(self, name: str) -> None:
        with self._lock:
            self._failures.pop(f"user:{name}", None)
