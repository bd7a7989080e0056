"""The first start: a one-time link on which the Administrator password is set (no default password exists).

While the data directory has no user and no password-less choice, the server makes one random token and prints
``http://HOST:PORT/setup?token=…`` on its console; the token works once and dies with the process (the next start
prints a new one). Whoever can read the server's console is taken to be its owner.
"""

from __future__ import annotations

import hmac
import secrets
import threading

from servostudio.errors import Forbidden


class SetupRefused(Forbidden):
    """The setup token is wrong, already used, or setup is over."""


class SetupLink:
    def __init__(self) -> None:
        self._token: str | None = None
        self._used = False
        self._lock = threading.Lock()

    def token(self) -> str:
        """The token of this process's setup link (the same one until it is used)."""
        with self._lock:
            if self._token is None:
                self._token = secrets.token_urlsafe(32)
            return self._token

    def redeem(self, token: str) -> None:
        """Accept the right token once; any other token is refused and leaves the right one valid (256 random bits
        cannot be guessed, and a wrong try must not lock the owner out)."""
        with self._lock:
            expected = None if self._used else self._token
            if expected is None or not hmac.compare_digest(token.encode(), expected.encode()):
                raise SetupRefused("the setup link is wrong or was used already; restart the server for a new one")
            self._used = True
