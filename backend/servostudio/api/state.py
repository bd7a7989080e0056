"""What one running server holds, typed and built in one place (``create_app``), so a route or a test reads it
through ``api.deps`` and never assembles it."""

from __future__ import annotations

from dataclasses import dataclass

from servostudio.od import EdsLibrary
from servostudio.services.bus import ConnectionManager, EventHub, JobRegistry
from servostudio.services.motion import MotionGuard
from servostudio.services.projects import ProjectService
from servostudio.services.settings import Settings


@dataclass(frozen=True)
class ServerState:
    settings: Settings
    library: EdsLibrary  # built-in dictionaries plus the user's imported ones
    connections: ConnectionManager  # the open buses, their drives and the event hub
    motion: MotionGuard  # live motion clients and the axes they answer for
    jobs: JobRegistry  # background backups, restores and commissioning
    projects: ProjectService  # the project store

    @classmethod
    def build(cls, settings: Settings) -> ServerState:
        library = EdsLibrary(settings.builtin_eds_dir, settings.user_eds_dir)
        connections = ConnectionManager(library)
        return cls(
            settings=settings,
            library=library,
            connections=connections,
            motion=MotionGuard(),
            jobs=JobRegistry(connections.events),
            projects=ProjectService(settings.projects_dir, library, settings.motors_dir),
        )

    @property
    def events(self) -> EventHub:
        return self.connections.events

    def open_buses(self) -> None:
        """The buses the server was started with (they connect in the background; a missing one retries)."""
        for spec in self.settings.buses:
            self.connections.open(spec, wait=0.0)

    def close(self) -> None:
        self.connections.close_all()
