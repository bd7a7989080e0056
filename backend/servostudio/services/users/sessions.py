"""Browser sessions, kept in the server's memory (a restart logs everyone out).

A session is a random id (the HttpOnly cookie) plus a CSRF token the page sends back in a header; it ends after
8 hours without a request, 24 hours after login at the latest, at logout, or when its user is removed.
"""

from __future__ import annotations

import secrets
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass

IDLE_SECONDS = 8 * 3600
LIFETIME_SECONDS = 24 * 3600


@dataclass
class Session:
    id: str
    user: str
    csrf: str
    created: float
    seen: float


class Sessions:
    def __init__(self, clock: Callable[[], float] = time.time) -> None:
        self.clock = clock
        self._sessions: dict[str, Session] = {}
        self._lock = threading.Lock()

    def open(self, user: str) -> Session:
        now = self.clock()
        session = Session(secrets.token_urlsafe(32), user, secrets.token_urlsafe(32), now, now)
        with self._lock:
            self._sessions[session.id] = session
        return session

    def find(self, session_id: str | None) -> Session | None:
        """The live session of that id (its idle time restarts), or None."""
        with self._lock:
            session = self._sessions.get(session_id or "")
            if session is None or self._over(session):
                self._sessions.pop(session_id or "", None)
                return None
            session.seen = self.clock()
            return session

    def _over(self, session: Session) -> bool:
        now = self.clock()
        return now - session.seen > IDLE_SECONDS or now - session.created > LIFETIME_SECONDS

    def close(self, session_id: str) -> None:
        with self._lock:
            self._sessions.pop(session_id, None)

    def close_user(self, user: str) -> None:
        with self._lock:
            for session_id in [key for key, session in self._sessions.items() if session.user == user]:
                del self._sessions[session_id]
