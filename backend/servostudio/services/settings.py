"""What the product was started with, read once: command-line flags over environment variables over defaults.

The environment is read when a ``Settings`` is built (``SERVOSTUDIO_EDS_DIR``, ``SERVOSTUDIO_USER_EDS_DIR`` or
``XDG_DATA_HOME``, ``SERVOSTUDIO_MOTORS_DIR``, ``SERVOSTUDIO_EXPORT_DIR``, ``SERVOSTUDIO_DATA_DIR``), never when a
module is imported, so a test or a second server in one process gets what it asks for.  The server
(``servostudio serve``) and the project and EDS commands build one from their flags; ``api.app.create_app`` builds
the server's state from it.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from servostudio.errors import InvalidInput
from servostudio.od.library import builtin_eds_dir, default_user_eds_dir
from servostudio.services.motion.guard import OLD_VALUES_UP_TO
from servostudio.services.projects.motors import builtin_motors_dir

#: the built browser UI (``npm run build`` writes it)
STATIC_DIR = Path(__file__).resolve().parent.parent / "static"
DEFAULT_HOST = "127.0.0.1"
DEFAULT_PORT = 8000


def default_data_dir(environ: Mapping[str, str] = os.environ) -> Path:
    """The server's own data (users, tokens, the password-less choice): ``SERVOSTUDIO_DATA_DIR``, else
    ``$XDG_DATA_HOME/servostudio`` (beside the imported EDS files), else ``~/.local/share/servostudio``."""
    data_home = Path(environ.get("XDG_DATA_HOME") or Path.home() / ".local" / "share")
    return Path(environ.get("SERVOSTUDIO_DATA_DIR") or data_home / "servostudio")


def default_export_dir() -> Path | None:
    """Where backup and restore jobs may also read and write besides the project store: ``SERVOSTUDIO_EXPORT_DIR``
    (none by default)."""
    configured = os.environ.get("SERVOSTUDIO_EXPORT_DIR")
    return Path(configured) if configured else None


#: which drive writes the audit log reads the old value of first (``--audit-old-values``): up to 16 objects at
#: once (a single edit, a small batch; a restore then logs ``old: null``), or every write (a restore takes ~1.4×)
AUDIT_OLD_VALUES = {"small-writes": OLD_VALUES_UP_TO, "every-write": None}


def default_audit_old_values() -> str:
    return os.environ.get("SERVOSTUDIO_AUDIT_OLD_VALUES", "small-writes")


class UnknownAuditChoice(InvalidInput):
    """An ``--audit-old-values`` / ``SERVOSTUDIO_AUDIT_OLD_VALUES`` that is not one of the choices."""


@dataclass(frozen=True)
class Settings:
    projects_dir: Path = Path("projects")
    static_dir: Path = STATIC_DIR
    builtin_eds_dir: Path = field(default_factory=builtin_eds_dir)
    user_eds_dir: Path = field(default_factory=default_user_eds_dir)
    motors_dir: Path = field(default_factory=builtin_motors_dir)
    export_dir: Path | None = field(default_factory=default_export_dir)
    buses: tuple[str, ...] = ()  # bus specs opened at startup
    shares: tuple[str, ...] = ()  # buses shared as socketcand endpoints at startup: "BUS=[HOST:]PORT" (``--share``)
    host: str = DEFAULT_HOST
    port: int = DEFAULT_PORT
    data_dir: Path = field(default_factory=default_data_dir)  # users.json: users, API tokens, password-less choice
    allowed_hosts: tuple[str, ...] = ()  # Host values accepted besides the loopback names and `host`
    allowed_origins: tuple[str, ...] = ()  # browser origins accepted besides the server's own
    audit_file: Path | None = None  # the audit log (JSON lines); None: ``audit.jsonl`` in ``data_dir``
    audit_old_values: str = field(default_factory=default_audit_old_values)  # a key of ``AUDIT_OLD_VALUES``

    def __post_init__(self) -> None:
        if self.audit_old_values not in AUDIT_OLD_VALUES:
            choices = ", ".join(AUDIT_OLD_VALUES)
            raise UnknownAuditChoice(f"audit old values {self.audit_old_values!r}: use one of {choices}")

    @property
    def old_values_up_to(self) -> int | None:
        """The largest write batch whose old values the audit log reads first (None: every batch)."""
        return AUDIT_OLD_VALUES[self.audit_old_values]

    @classmethod
    def given(cls, **flags: Any) -> Settings:
        """Settings from command-line flags; a flag left out (None) keeps its environment or default value."""
        return replace(cls(), **{name: value for name, value in flags.items() if value is not None})

    @property
    def audit_path(self) -> Path:
        """Where the audit log is appended: ``audit_file``, else ``DATA_DIR/audit.jsonl``."""
        return self.audit_file if self.audit_file is not None else self.data_dir / "audit.jsonl"

    @property
    def transfer_roots(self) -> tuple[Path, ...]:
        """The directories backup and restore jobs may use: the project store and the export directory."""
        return (self.projects_dir,) if self.export_dir is None else (self.projects_dir, self.export_dir)
