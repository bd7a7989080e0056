"""Who may come in: logins and sessions, API tokens, the first-start setup and the password-less local mode.

One ``AccessControl`` per server (``ServerState.access``); the API asks it who a request's caller is, and the
routes and WebSocket messages then compare that caller's level with what they declare.
"""

from __future__ import annotations

import time
from collections.abc import Callable

from servostudio.errors import Unauthenticated
from servostudio.services.users import passwords
from servostudio.services.users.binding import is_loopback
from servostudio.services.users.levels import LOCAL_ADMINISTRATOR, Level, User, require
from servostudio.services.users.sessions import Session, Sessions
from servostudio.services.users.setup import SetupLink, SetupRefused
from servostudio.services.users.store import TOKEN_DAYS_DEFAULT, ApiToken, PasswordlessRefused, UserStore
from servostudio.services.users.throttle import LoginThrottle
from servostudio.services.users.tokens import UnknownToken


class WrongPassword(Unauthenticated):
    """The user name or the password is wrong (which of the two is not said)."""


class AccessControl:
    def __init__(self, store: UserStore, bind_host: str, clock: Callable[[], float] = time.time) -> None:
        self.store, self.bind_host = store, bind_host
        self.sessions = Sessions(clock)
        self.throttle = LoginThrottle()
        self.setup = SetupLink()

    # ---- who is calling --------------------------------------------------------------------------------------

    def login(self, name: str, password: str, address: str) -> tuple[Session, User]:
        """A new session for the user, if the password is right and the rate limits allow the try."""
        user = self._verified(name, password, address)
        return self.sessions.open(user.name), user

    def change_password(self, user: User, current: str, new: str, address: str) -> None:
        """One's own password, the current one asked again (and rate-limited like a login)."""
        self._verified(user.name, current, address)
        self.store.set_password(user.name, new)

    def _verified(self, name: str, password: str, address: str) -> User:
        self.throttle.check(name, address)
        user = self.store.authenticate(name, password)
        if user is None:
            self.throttle.failed(name, address)
            raise WrongPassword("wrong user name or password")
        self.throttle.succeeded(name)
        return user

    def session_caller(self, session: Session) -> User | None:
        """The session's user as the store has it now (a removed user's session ends, a new level applies)."""
        user = self.store.user(session.user)
        if user is None:
            self.sessions.close(session.id)
        return user

    def token_caller(self, text: str) -> User:
        return self.store.token_caller(text)

    def passwordless_caller(self, address: str | None) -> User | None:
        """The local administrator, when the owner chose password-less mode and the caller is on this machine."""
        if self.store.contents().passwordless and address is not None and is_loopback(address):
            return LOCAL_ADMINISTRATOR
        return None

    # ---- first start ---------------------------------------------------------------------------------------------

    def setup_link(self, base_url: str) -> str | None:
        """The one-time link to print at start, while setup is needed."""
        return f"{base_url}/setup?token={self.setup.token()}" if self.store.needs_setup else None

    def set_up_administrator(self, token: str, name: str, password: str) -> tuple[Session, User]:
        """The first administrator, logged in at once; the password is checked before the token is spent."""
        passwords.check_strength(password)
        self._redeem(token)
        account = self.store.add_user(name, Level.ADMINISTRATOR, password)
        return self.sessions.open(account.name), User(account.name, account.level)

    def set_up_passwordless(self, token: str) -> None:
        if not is_loopback(self.bind_host):
            raise PasswordlessRefused(f"password-less mode needs a loopback address, not {self.bind_host}")
        self._redeem(token)
        self.store.choose_passwordless()

    def _redeem(self, token: str) -> None:
        if not self.store.needs_setup:
            raise SetupRefused("setup is done: log in instead")
        self.setup.redeem(token)

    # ---- tokens made by a caller ---------------------------------------------------------------------------

    def create_token(
        self, caller: User, level: Level, days: int = TOKEN_DAYS_DEFAULT, label: str = ""
    ) -> tuple[str, ApiToken]:
        """A token for ``caller``'s scripts, at most at its own level (its text is returned once)."""
        require(caller, level, f"a token at the {level} level")
        return self.store.create_token(level, days, owner=caller.name, label=label)

    def visible_tokens(self, caller: User) -> list[ApiToken]:
        """An administrator sees every token, anyone else its own."""
        records = self.store.contents().tokens
        return [token for token in records if self._manages(caller, token)]

    def revoke_token(self, caller: User, token_id: str) -> None:
        if not any(token.id == token_id for token in self.visible_tokens(caller)):
            raise UnknownToken(f"no token {token_id!r}")
        self.store.revoke_token(token_id)

    @staticmethod
    def _manages(caller: User, token: ApiToken) -> bool:
        return caller.level is Level.ADMINISTRATOR or token.owner == caller.name

    def remove_user(self, name: str) -> None:
        self.store.remove_user(name)
        self.sessions.close_user(name)
