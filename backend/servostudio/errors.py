"""One error taxonomy for the whole product, like python-can's ``CanError`` or canopen's ``SdoError`` roots.

Every refusal or failure Servo Studio raises on purpose is a :class:`ServoStudioError`, and its :class:`ErrorKind`
says what the caller can do about it: fix the name (not found), fix the request (invalid input, too large), resolve
the state first (conflict, refused for safety), or check the link and retry (communication, unavailable, timeout).
Each error class derives from the category class of its kind, listed first among its bases; a class keeps its
historical base (``ValueError``, ``LookupError``, …) after it, so existing ``except`` clauses still hold.

``OUTCOMES`` is the one table from kind to HTTP status and CLI exit code; the API and the CLI only look it up.  An
exception outside the taxonomy is a bug: ``INTERNAL`` (HTTP 500 with a request id, exit code 70, logged).
"""

from __future__ import annotations

import enum
from dataclasses import dataclass


class ErrorKind(enum.StrEnum):
    NOT_FOUND = "not_found"
    INVALID_INPUT = "invalid_input"
    TOO_LARGE = "too_large"
    CONFLICT = "conflict"
    REFUSED_FOR_SAFETY = "refused_for_safety"
    COMMUNICATION = "communication"
    UNAVAILABLE = "unavailable"
    TIMEOUT = "timeout"
    UNAUTHENTICATED = "unauthenticated"
    FORBIDDEN = "forbidden"
    RATE_LIMITED = "rate_limited"
    INTERNAL = "internal"  # no error class: any exception outside the taxonomy


@dataclass(frozen=True)
class Outcome:
    http_status: int
    exit_code: int
    meaning: str


#: kind → what the API answers and the CLI exits with (exit 3: refused, nothing written; 4: not found; 5: the
#: bus or the drive failed; 6: who the caller is could not be established; 7: the caller may not do it; 70:
#: internal software error, sysexits' EX_SOFTWARE)
OUTCOMES: dict[ErrorKind, Outcome] = {
    ErrorKind.NOT_FOUND: Outcome(404, 4, "unknown bus, node, job, object, device, project, axis or motor"),
    ErrorKind.INVALID_INPUT: Outcome(422, 3, "refused before anything was sent or written"),
    ErrorKind.TOO_LARGE: Outcome(413, 3, "an upload larger than its limit; nothing was kept"),
    ErrorKind.CONFLICT: Outcome(409, 3, "the current state refuses it: a changed project, a taken name, the drive"),
    ErrorKind.REFUSED_FOR_SAFETY: Outcome(409, 3, "refused to keep the machine safe (no live client, drive enabled)"),
    ErrorKind.COMMUNICATION: Outcome(502, 5, "the drive or the link failed part-way (incomplete backup or restore)"),
    ErrorKind.UNAVAILABLE: Outcome(503, 5, "the bus is not connected, or an axis's drive cannot be reached"),
    ErrorKind.TIMEOUT: Outcome(504, 5, "the drive did not answer in time"),
    ErrorKind.UNAUTHENTICATED: Outcome(401, 6, "no valid session or token (log in, or pass a live API token)"),
    ErrorKind.FORBIDDEN: Outcome(403, 7, "the caller's level is too low, or a foreign page, Host or Origin"),
    ErrorKind.RATE_LIMITED: Outcome(429, 6, "too many failed logins from this user or address; wait and retry"),
    ErrorKind.INTERNAL: Outcome(500, 70, "a bug: logged with the request id"),
}


class ServoStudioError(Exception):
    """Root of every error the product raises on purpose; ``kind`` decides the HTTP status and the exit code."""

    kind: ErrorKind

    @property
    def outcome(self) -> Outcome:
        return OUTCOMES[self.kind]


class NotFound(ServoStudioError, LookupError):
    """The bus, node, job, object or project the caller named does not exist."""

    kind = ErrorKind.NOT_FOUND


class InvalidInput(ServoStudioError, ValueError):
    """Input refused before anything was sent or written (a name, a value, a file, an option)."""

    kind = ErrorKind.INVALID_INPUT


class TooLarge(ServoStudioError):
    """An upload exceeds its size limit; it was refused before it was kept."""

    kind = ErrorKind.TOO_LARGE


class Conflict(ServoStudioError):
    """The current state refuses the request (a project changed meanwhile, a name taken, a drive that refused)."""

    kind = ErrorKind.CONFLICT


class RefusedForSafety(ServoStudioError):
    """Refused so that no axis moves without someone answering for it, or a drive is not changed while enabled."""

    kind = ErrorKind.REFUSED_FOR_SAFETY


class CommunicationError(ServoStudioError):
    """The bus or the drive failed during the work; what was done is reported."""

    kind = ErrorKind.COMMUNICATION


class Unavailable(ServoStudioError):
    """The bus is not connected (or an axis's drive cannot be reached); retry when it is back."""

    kind = ErrorKind.UNAVAILABLE


class Timeout(ServoStudioError):
    """The drive did not answer in time (absent, unpowered, or the link is broken)."""

    kind = ErrorKind.TIMEOUT


class Unauthenticated(ServoStudioError):
    """The request carries no valid session or API token (or a wrong password): nothing was done."""

    kind = ErrorKind.UNAUTHENTICATED


class Forbidden(ServoStudioError):
    """The caller is known but may not do this (level too low), or the request comes from a foreign page."""

    kind = ErrorKind.FORBIDDEN


class RateLimited(ServoStudioError):
    """Too many failed logins in a row: this user or address must wait before the next try."""

    kind = ErrorKind.RATE_LIMITED

    def __init__(self, message: str, retry_after: float) -> None:
        super().__init__(message)
        #: seconds until the next try may succeed (the HTTP answer's ``Retry-After``)
        self.retry_after = retry_after
