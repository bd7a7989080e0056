"""Password hashing with Argon2id (``pwdlib``; the parameters are the argon2 library's RFC 9106 defaults).

Only hashes are stored. A login for an unknown name still verifies against a dummy hash, so the answer takes as
long as for a known name and does not tell which names exist.
"""

from __future__ import annotations

from functools import cache

from pwdlib import PasswordHash
from pwdlib.hashers.argon2 import Argon2Hasher

from servostudio.errors import InvalidInput

MIN_LENGTH = 10
MAX_LENGTH = 1024  # a bound on the work one login may cost


class WeakPassword(InvalidInput):
    """A password too short (or absurdly long) to be accepted."""


_HASHER = PasswordHash((Argon2Hasher(),))


def check_strength(password: str) -> None:
    if len(password) < MIN_LENGTH:
        raise WeakPassword(f"a password needs at least {MIN_LENGTH} characters")
    if len(password) > MAX_LENGTH:
        raise WeakPassword(f"a password has at most {MAX_LENGTH} characters")


def hash_password(password: str) -> str:
    check_strength(password)
    return _HASHER.hash(password)


def verify(password: str, stored: str | None) -> bool:
    """Whether ``password`` matches ``stored``; None (no such user) costs the same time and is False."""
    if len(password) > MAX_LENGTH:
        return False
    matches = _HASHER.verify(password, stored or _dummy_hash())
    return matches and stored is not None


@cache
def _dummy_hash() -> str:
    return _HASHER.hash("no user has this password")
