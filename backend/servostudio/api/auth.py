"""Who a request's caller is: an API token, a browser session, or the password-less local administrator.

- ``Authorization: Bearer sst_…``: scripts and the CLI. Exempt from the CSRF check: a foreign page cannot make a
  browser attach it. A token that is wrong or expired is refused, never ignored.
- The session cookie (HttpOnly, SameSite=Strict, Secure over TLS) set by ``POST /api/session``: the browser UI.
  A state-changing request must repeat the session's CSRF token in ``X-CSRF-Token``; the page reads it from the
  ``servostudio_csrf`` cookie, which only a page of this origin can read.
- Password-less mode (chosen at setup, loopback only): a caller on this machine is the local administrator.

Anything else is 401 ``unauthenticated``. Host and Origin are checked before any of this (``api.security``).
"""

from __future__ import annotations

import hmac
import sys

from starlette.requests import HTTPConnection
from starlette.responses import Response

from servostudio.errors import Forbidden, Unauthenticated
from servostudio.services.settings import Settings
from servostudio.services.users import AccessControl, Session, User, is_loopback
from servostudio.services.users.sessions import LIFETIME_SECONDS

SESSION_COOKIE = "servostudio_session"
CSRF_COOKIE = "servostudio_csrf"
CSRF_HEADER = "X-CSRF-Token"
SAFE_METHODS = frozenset({"GET", "HEAD", "OPTIONS"})


class NotLoggedIn(Unauthenticated):
    """No token, no live session, and no password-less mode for this caller."""


class CsrfRefused(Forbidden):
    """A cookie-session request that changes something without the session's CSRF token."""


def identify(connection: HTTPConnection, access: AccessControl) -> User:
    """The caller of an HTTP request or a WebSocket."""
    bearer = _bearer(connection)
    if bearer is not None:
        return access.token_caller(bearer)
    session = access.sessions.find(connection.cookies.get(SESSION_COOKIE))
    user = access.session_caller(session) if session else None
    if session is not None and user is not None:
        _check_csrf(connection, session)
        return user
    local = access.passwordless_caller(connection.client.host if connection.client else None)
    if local is not None:
        return local
    raise NotLoggedIn("log in (POST /api/session) or send an API token (Authorization: Bearer …)")


def _bearer(connection: HTTPConnection) -> str | None:
    header = connection.headers.get("authorization")
    if header is None:
        return None
    scheme, _, value = header.partition(" ")
    if scheme.lower() != "bearer" or not value.strip():
        raise NotLoggedIn("the Authorization header must be 'Bearer <API token>'")
    return value.strip()


def _check_csrf(connection: HTTPConnection, session: Session) -> None:
    """WebSockets carry no custom header: their upgrade is covered by the Origin check and SameSite=Strict."""
    if connection.scope["type"] != "http" or connection.scope["method"] in SAFE_METHODS:
        return
    sent = connection.headers.get(CSRF_HEADER, "")
    if not hmac.compare_digest(sent.encode(), session.csrf.encode()):
        raise CsrfRefused(f"a change from a browser session needs the {CSRF_HEADER} header (the page's CSRF token)")


def set_session_cookies(response: Response, session: Session, secure: bool) -> None:
    """The session (HttpOnly: no script reads it) and its CSRF token (readable by this origin's page only)."""
    for name, value, http_only in ((SESSION_COOKIE, session.id, True), (CSRF_COOKIE, session.csrf, False)):
        response.set_cookie(
            name, value, max_age=LIFETIME_SECONDS, path="/", secure=secure, httponly=http_only, samesite="strict"
        )


def clear_session_cookies(response: Response, secure: bool) -> None:
    for name in (SESSION_COOKIE, CSRF_COOKIE):
        response.delete_cookie(name, path="/", secure=secure, httponly=name == SESSION_COOKIE, samesite="strict")


def is_tls(connection: HTTPConnection) -> bool:
    return connection.url.scheme in ("https", "wss")


def announce_setup(access: AccessControl, settings: Settings) -> None:
    """First start: print the one-time setup link on the server's console, which only the machine's owner sees."""
    host = settings.host if is_loopback(settings.host) else "127.0.0.1"
    link = access.setup_link(f"http://{f'[{host}]' if ':' in host else host}:{settings.port}")
    if link is not None:
        print(
            f"Servo Studio has no users yet. Set the Administrator password (or choose password-less use on this "
            f"machine) once, at\n    {link}\nor run: servostudio user add NAME --level administrator",
            file=sys.stderr,
            flush=True,
        )
