"""API tokens for scripts and the CLI (``Authorization: Bearer sst_<id>_<secret>``).

The id finds the record; the secret (256 random bits) is checked against its SHA-256, compared in constant time.
The text is shown once, when the token is made; the store keeps only the digest.
"""

from __future__ import annotations

import hashlib
import hmac
import secrets

from servostudio.errors import NotFound, Unauthenticated

PREFIX = "sst"


class InvalidToken(Unauthenticated):
    """A Bearer token that is malformed, unknown, revoked or expired."""


class UnknownToken(NotFound):
    """No token of that id (to revoke)."""


def new_token() -> tuple[str, str, str]:
    """``(id, secret, text)`` of a fresh token."""
    token_id, secret = secrets.token_hex(6), secrets.token_urlsafe(32)
    return token_id, secret, f"{PREFIX}_{token_id}_{secret}"


def parse(text: str) -> tuple[str, str]:
    """``(id, secret)`` of a token's text."""
    parts = text.strip().split("_", 2)
    if len(parts) != 3 or parts[0] != PREFIX or not parts[1] or not parts[2]:
        raise InvalidToken("not a Servo Studio API token (sst_…)")
    return parts[1], parts[2]


def digest(secret: str) -> str:
    return hashlib.sha256(secret.encode()).hexdigest()


def matches(secret: str, stored_digest: str) -> bool:
    return hmac.compare_digest(digest(secret), stored_digest)
