"""Users, levels and access: who may do what on this server (``docs/security.md``).

- ``levels``: the four levels, the caller (``User``) and the level each dictionary entry needs to be written;
- ``store``: users and API tokens in the data directory's ``users.json`` (``storefile``: atomic, 0600, locked);
- ``passwords`` (Argon2id), ``tokens`` (Bearer tokens), ``sessions`` (browser sessions), ``throttle`` (login
  rate limits), ``setup`` (the first start's one-time link), ``binding`` (which addresses the server may serve);
- ``access``: ``AccessControl``, what the API asks who a caller is.
"""

from servostudio.services.users.access import AccessControl, WrongPassword
from servostudio.services.users.binding import RemoteBindRefused, check_bind, is_loopback
from servostudio.services.users.levels import (
    LOCAL_ADMINISTRATOR,
    WRITE_RULES,
    Level,
    LevelTooLow,
    User,
    check_write,
    require,
    write_level,
)
from servostudio.services.users.sessions import Session
from servostudio.services.users.store import TOKEN_DAYS_DEFAULT, ApiToken, UserStore

__all__ = [
    "LOCAL_ADMINISTRATOR",
    "TOKEN_DAYS_DEFAULT",
    "WRITE_RULES",
    "AccessControl",
    "ApiToken",
    "Level",
    "LevelTooLow",
    "RemoteBindRefused",
    "Session",
    "User",
    "UserStore",
    "WrongPassword",
    "check_bind",
    "check_write",
    "is_loopback",
    "require",
    "write_level",
]
