"""Users and API tokens of one server, kept in ``users.json`` in the server's data directory.

What is stored: each user's name, level and Argon2id password hash; each API token's id, label, level, owner,
expiry and the SHA-256 of its secret (a token is 256 random bits, so a fast hash is as strong as a slow one and
costs nothing per request); and whether the user chose the password-less single-user mode at setup. Adding the
first user ends that mode. Nothing in the file is a usable secret.
"""

from __future__ import annotations

import dataclasses
import re
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from servostudio.errors import Conflict, InvalidInput, NotFound
from servostudio.services.users import passwords, tokens
from servostudio.services.users.levels import LOCAL_ADMINISTRATOR, Level, User
from servostudio.services.users.storefile import UserStoreUnreadable, locked, read_json, signature, write_json

STORE_FILE = "users.json"
FORMAT = 1
USER_NAME = re.compile(r"^[a-z][a-z0-9_.-]{0,31}$")
DAY = 86_400.0
TOKEN_DAYS_DEFAULT = 30
TOKEN_DAYS_MAX = 365


class UnknownUser(NotFound):
    """No user of that name."""


class UserExists(Conflict):
    """A user of that name exists already."""


class LastAdministrator(Conflict):
    """The change would leave no administrator, and nobody could manage users any more."""


class PasswordlessRefused(Conflict):
    """Password-less mode is for a server without users; this one has some."""


class BadUserName(InvalidInput):
    """A user name outside the allowed characters."""


@dataclass(frozen=True)
class Account:
    name: str
    level: Level
    password_hash: str
    created: float

    def public(self) -> dict[str, object]:
        return {"name": self.name, "level": self.level, "created": self.created}


@dataclass(frozen=True)
class ApiToken:
    id: str
    label: str
    level: Level
    owner: str | None  # the user who created it; None: made from the data directory by the machine's owner
    digest: str
    created: float
    expires: float

    def public(self) -> dict[str, object]:
        return {key: value for key, value in dataclasses.asdict(self).items() if key != "digest"}

    @property
    def caller(self) -> User:
        return User(name=self.owner or f"token-{self.id}", level=self.level)


@dataclass(frozen=True)
class Contents:
    passwordless: bool = False
    accounts: tuple[Account, ...] = ()
    tokens: tuple[ApiToken, ...] = ()

    def account(self, name: str) -> Account | None:
        return next((account for account in self.accounts if account.name == name), None)

    def administrators(self) -> int:
        return sum(account.level is Level.ADMINISTRATOR for account in self.accounts)


class UserStore:
    """The users and tokens of the data directory; every change is written to disk before it returns."""

    def __init__(self, data_dir: Path, clock: Callable[[], float] = time.time) -> None:
        self.path = Path(data_dir) / STORE_FILE
        self.clock = clock
        self._cached: tuple[tuple[int, int, int] | None, Contents] = (None, Contents())

    def contents(self) -> Contents:
        """What the file holds now (re-read only when the file changed since the last read)."""
        current = signature(self.path)
        if current is None:
            return Contents()
        if current != self._cached[0]:
            self._cached = (current, _decode(read_json(self.path) or {}))
        return self._cached[1]

    def _change(self, edit: Callable[[Contents], Contents]) -> Contents:
        with locked(self.path):
            changed = edit(_decode(read_json(self.path) or {}))
            write_json(self.path, _encode(changed))
        return changed

    @property
    def needs_setup(self) -> bool:
        """First start: no user and no password-less choice yet."""
        contents = self.contents()
        return not contents.accounts and not contents.passwordless

    # ---- users -------------------------------------------------------------------------------------------------

    def add_user(self, name: str, level: Level, password: str) -> Account:
        account = Account(_user_name(name), level, passwords.hash_password(password), self.clock())

        def add(contents: Contents) -> Contents:
            if contents.account(account.name):
                raise UserExists(f"user {account.name!r} exists already")
            return Contents(False, (*contents.accounts, account), contents.tokens)

        self._change(add)
        return account

    def remove_user(self, name: str) -> None:
        """Remove the user and every token it created."""

        def remove(contents: Contents) -> Contents:
            _keeps_an_administrator(contents, _existing(contents, name), None)
            accounts = tuple(account for account in contents.accounts if account.name != name)
            return Contents(contents.passwordless, accounts, tuple(t for t in contents.tokens if t.owner != name))

        self._change(remove)

    def set_level(self, name: str, level: Level) -> Account:
        return self._replace_account(name, lambda account: dataclasses.replace(account, level=level))

    def set_password(self, name: str, password: str) -> Account:
        digest = passwords.hash_password(password)
        return self._replace_account(name, lambda account: dataclasses.replace(account, password_hash=digest))

    def _replace_account(self, name: str, change: Callable[[Account], Account]) -> Account:
        def replace(contents: Contents) -> Contents:
            new = change(_existing(contents, name))
            _keeps_an_administrator(contents, _existing(contents, name), new)
            accounts = tuple(new if account.name == name else account for account in contents.accounts)
            return Contents(contents.passwordless, accounts, contents.tokens)

        return _existing(self._change(replace), name)

    def authenticate(self, name: str, password: str) -> User | None:
        """The user whose name and password these are, or None (timing does not tell which part was wrong)."""
        account = self.contents().account(name)
        if not passwords.verify(password, account.password_hash if account else None) or account is None:
            return None
        return User(account.name, account.level)

    def account(self, name: str) -> Account:
        return _existing(self.contents(), name)

    def user(self, name: str) -> User | None:
        account = self.contents().account(name)
        return User(account.name, account.level) if account else None

    # ---- API tokens ----------------------------------------------------------------------------------------------

    def create_token(
        self, level: Level, days: int = TOKEN_DAYS_DEFAULT, owner: str | None = None, label: str = ""
    ) -> tuple[str, ApiToken]:
        """A new token; its text is returned here once and never stored."""
        now = self.clock()
        token_id, secret, text = tokens.new_token()
        record = ApiToken(token_id, label, level, owner, tokens.digest(secret), now, now + _token_days(days) * DAY)
        self._change(lambda contents: _with_tokens(contents, (*_live(contents.tokens, now), record)))
        return text, record

    def revoke_token(self, token_id: str) -> None:
        def revoke(contents: Contents) -> Contents:
            if not any(token.id == token_id for token in contents.tokens):
                raise tokens.UnknownToken(f"no token {token_id!r}")
            return _with_tokens(contents, tuple(token for token in contents.tokens if token.id != token_id))

        self._change(revoke)

    def token_caller(self, text: str) -> User:
        """The caller a Bearer token stands for; refused when unknown, revoked or expired."""
        token_id, secret = tokens.parse(text)
        record = next((token for token in self.contents().tokens if token.id == token_id), None)
        if record is None or not tokens.matches(secret, record.digest):
            raise tokens.InvalidToken("the API token is unknown or revoked")
        if record.expires <= self.clock():
            raise tokens.InvalidToken(f"the API token {token_id} has expired; create a new one")
        return record.caller

    # ---- password-less single-user mode ----------------------------------------------------------------------

    def choose_passwordless(self) -> None:
        def choose(contents: Contents) -> Contents:
            if contents.accounts:
                raise PasswordlessRefused("this server has users: password-less mode is only for a server without")
            return Contents(True, (), contents.tokens)

        self._change(choose)


def _user_name(name: str) -> str:
    if not USER_NAME.match(name):
        raise BadUserName(f"user name {name!r}: 1-32 of a-z 0-9 _ . - starting with a letter")
    if name == LOCAL_ADMINISTRATOR.name:
        raise BadUserName(f"{name!r} is the password-less mode's user; choose another name")
    return name


def _existing(contents: Contents, name: str) -> Account:
    account = contents.account(name)
    if account is None:
        raise UnknownUser(f"no user {name!r}")
    return account


def _keeps_an_administrator(contents: Contents, old: Account, new: Account | None) -> None:
    losing = old.level is Level.ADMINISTRATOR and (new is None or new.level is not Level.ADMINISTRATOR)
    if losing and contents.administrators() == 1:
        raise LastAdministrator(f"{old.name} is the last administrator; make another one first")


def _token_days(days: int) -> int:
    if not 1 <= days <= TOKEN_DAYS_MAX:
        raise InvalidInput(f"a token expires after 1 to {TOKEN_DAYS_MAX} days, not {days}")
    return days


def _live(records: tuple[ApiToken, ...], now: float) -> tuple[ApiToken, ...]:
    """Expired tokens are dropped whenever the tokens change."""
    return tuple(record for record in records if record.expires > now)


def _with_tokens(contents: Contents, records: tuple[ApiToken, ...]) -> Contents:
    return Contents(contents.passwordless, contents.accounts, records)


def _encode(contents: Contents) -> dict[str, Any]:
    return {
        "format": FORMAT,
        "passwordless": contents.passwordless,
        "users": [dataclasses.asdict(account) for account in contents.accounts],
        "tokens": [dataclasses.asdict(token) for token in contents.tokens],
    }


def _decode(data: dict[str, Any]) -> Contents:
    try:
        accounts = tuple(Account(**{**row, "level": Level(row["level"])}) for row in data.get("users", []))
        records = tuple(ApiToken(**{**row, "level": Level(row["level"])}) for row in data.get("tokens", []))
    except (TypeError, KeyError, ValueError) as error:
        raise UserStoreUnreadable(f"{STORE_FILE}: unexpected content ({error}); fix or remove it") from None
    return Contents(bool(data.get("passwordless", False)), accounts, records)
