"""What the server was started with (``GET /api/server/settings``, Administrator): its flags over its environment
over the defaults, as ``Settings`` holds them — read-only, since they are read once at start (``docs/security.md``).

``Settings`` holds no secret (passwords and token digests live in the data directory's ``users.json``, which this
does not read); a bus spec naming a URL with a user and password (``serial:rfc2217://user:secret@host``) is shown
with its credentials masked all the same.
"""

from __future__ import annotations

import re

from fastapi import APIRouter
from pydantic import BaseModel, Field

from servostudio import __version__
from servostudio.api.deps import Access, Server
from servostudio.api.security import Requires
from servostudio.services.settings import Settings
from servostudio.services.users import Level

router = APIRouter(tags=["server"])
_CREDENTIALS = re.compile(r"(?<=//)[^/@\s]+@")


class ServerSettingsModel(BaseModel):
    version: str
    host: str = Field(description="the address the server listens on (`serve --host`)")
    port: int
    projects_dir: str = Field(description="the project store (`--projects`)")
    export_dir: str | None = Field(description="where backup and restore jobs may also write (`--export-dir`)")
    data_dir: str = Field(description="users, tokens and the audit log (`--data-dir`, `SERVOSTUDIO_DATA_DIR`)")
    audit_file: str = Field(description="the audit log the server appends to")
    audit_old_values: str = Field(
        description="which drive writes the audit log reads the old value of first (`--audit-old-values`): "
        "`small-writes` (up to 16 objects at once) or `every-write`"
    )
    builtin_eds_dir: str
    user_eds_dir: str = Field(description="where imported EDS files go")
    motors_dir: str
    buses: list[str] = Field(description="bus specs opened at start (`--bus`); credentials in a URL masked")
    shares: list[str] = Field(description="buses shared as socketcand endpoints at start (`--share BUS=PORT`)")
    allowed_hosts: list[str] = Field(description="Host values accepted besides the loopback names (`--allowed-host`)")
    allowed_origins: list[str] = Field(description="browser origins accepted besides the server's own")
    passwordless: bool = Field(description="the password-less single-user mode chosen at setup")


def _masked(spec: str) -> str:
    return _CREDENTIALS.sub("***@", spec)


def shown(settings: Settings, passwordless: bool) -> dict[str, object]:
    """The settings as the route shows them: paths as text, specs with credentials masked."""
    return {
        "version": __version__,
        "host": settings.host,
        "port": settings.port,
        "projects_dir": str(settings.projects_dir),
        "export_dir": str(settings.export_dir) if settings.export_dir is not None else None,
        "data_dir": str(settings.data_dir),
        "audit_file": str(settings.audit_path),
        "audit_old_values": settings.audit_old_values,
        "builtin_eds_dir": str(settings.builtin_eds_dir),
        "user_eds_dir": str(settings.user_eds_dir),
        "motors_dir": str(settings.motors_dir),
        "buses": [_masked(spec) for spec in settings.buses],
        "shares": [_masked(share) for share in settings.shares],
        "allowed_hosts": list(settings.allowed_hosts),
        "allowed_origins": list(settings.allowed_origins),
        "passwordless": passwordless,
    }


@router.get(
    "/server/settings",
    response_model=ServerSettingsModel,
    summary="What the server was started with (read-only; no secrets)",
    dependencies=[Requires(Level.ADMINISTRATOR)],
)
def get_settings(server: Server, access: Access) -> dict[str, object]:
    return shown(server.settings, access.store.contents().passwordless)
