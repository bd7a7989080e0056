"""What one running server holds, typed and built in one place (``create_app``), so a route or a test reads it
through ``api.deps`` and never assembles it."""

from __future__ import annotations

from dataclasses import dataclass, field

from servostudio.od import EdsLibrary
from servostudio.services.audit import AuditLog
from servostudio.services.bus import ConnectionManager, EventHub, JobRegistry, parse_share
from servostudio.services.motion import MotionGuard
from servostudio.services.projects import ProjectService
from servostudio.services.scope import ScopeService
from servostudio.services.settings import Settings
from servostudio.services.users import AccessControl, UserStore


@dataclass(frozen=True)
class ServerState:
    settings: Settings
    library: EdsLibrary  # built-in dictionaries plus the user's imported ones
    connections: ConnectionManager  # the open buses, their drives and the event hub
    motion: MotionGuard  # the write gate of every drive: live clients, armed axes, the verdict on motion
    audit: AuditLog  # who wrote what to drives and projects, every motion start and stop (docs/security.md)
    jobs: JobRegistry  # background backups, restores and commissioning
    projects: ProjectService  # the project store
    access: AccessControl  # users, sessions, API tokens, the first-start setup (docs/security.md)
    scope: ScopeService = field(default_factory=ScopeService)  # oscilloscope capture jobs, the latest captures

    @classmethod
    def build(cls, settings: Settings) -> ServerState:
        library = EdsLibrary(settings.builtin_eds_dir, settings.user_eds_dir)
        audit, events = AuditLog(settings.audit_path), EventHub()
        motion = MotionGuard(events.publish, audit, settings.old_values_up_to)
        connections = ConnectionManager(library, events, motion)
        return cls(
            settings=settings,
            library=library,
            connections=connections,
            motion=motion,
            audit=audit,
            jobs=JobRegistry(connections.events),
            projects=ProjectService(settings.projects_dir, library, settings.motors_dir, audit),
            access=AccessControl(UserStore(settings.data_dir), settings.host),
        )

    @property
    def events(self) -> EventHub:
        return self.connections.events

    def open_buses(self) -> None:
        """The buses the server was started with (they connect in the background; a missing one retries)."""
        for spec in self.settings.buses:
            self.connections.open(spec, wait=0.0)
        for share in self.settings.shares:  # the user's opt-in, per bus (``serve --share BUS=PORT``)
            self.connections.share(*parse_share(share))

    def close(self) -> None:
        """Close every bus, then end the motion guard's threads (the hold-to-run watchdog stops what expires while
        the buses close)."""
        self.connections.close_all()
        self.motion.close()
