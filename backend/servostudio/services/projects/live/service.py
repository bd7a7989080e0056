"""One entry point for the live project operations (API and CLI): a project service plus the server's buses."""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence

from servostudio.services.bus import ConnectionManager, Job, JobRegistry
from servostudio.services.cancel import Cancellation
from servostudio.services.projects.live.commission import CommissionReport, Progress, commission
from servostudio.services.projects.live.links import AxisLink, link_axis
from servostudio.services.projects.live.motorlive import select_motor_live
from servostudio.services.projects.live.scaninto import ScanReport, scan_into_project
from servostudio.services.projects.live.sync import (
    DriveWriteReport,
    LiveCompare,
    compare_with_drive,
    take_from_drive,
    write_to_drive,
)
from servostudio.services.projects.parameters import ParameterChange
from servostudio.services.projects.service import AxisChoice, ProjectService


class LiveProjects:
    """Projects with their drives. ``buses`` maps a project bus name to another spec for this call."""

    def __init__(self, projects: ProjectService, connections: ConnectionManager) -> None:
        self.projects = projects
        self.connections = connections

    def link(self, project: str, axis: str, buses: Mapping[str, str] | None = None) -> AxisLink:
        return link_axis(self.projects.store.open(project).project, self.connections, axis, buses)

    def compare(
        self,
        project: str,
        axis: str,
        *,
        group: str | None = None,
        only_differences: bool = False,
        buses: Mapping[str, str] | None = None,
        read_only: bool = False,
    ) -> LiveCompare:
        return compare_with_drive(
            self.projects.parameters,
            project,
            self.link(project, axis, buses),
            group=group,
            only_differences=only_differences,
            read_only=read_only,
        )

    def take(
        self,
        project: str,
        axis: str,
        addresses: Sequence[str] | None = None,
        expected_revision: str | None = None,
        buses: Mapping[str, str] | None = None,
    ) -> ParameterChange:
        return take_from_drive(
            self.projects.parameters, project, self.link(project, axis, buses), addresses, expected_revision
        )

    def write(
        self,
        project: str,
        axis: str,
        addresses: Sequence[str] | None = None,
        store: bool = False,
        buses: Mapping[str, str] | None = None,
    ) -> DriveWriteReport:
        return write_to_drive(self.projects.parameters, project, self.link(project, axis, buses), addresses, store)

    def commission(
        self,
        project: str,
        direction: str = "check",
        axes: Iterable[str] | None = None,
        expected_revision: str | None = None,
        buses: Mapping[str, str] | None = None,
        progress: Progress | None = None,
        cancel: Cancellation | None = None,
    ) -> CommissionReport:
        return commission(
            self.projects, self.connections, project, direction, axes, buses, expected_revision, progress, cancel
        )

    def start_commission(
        self,
        jobs: JobRegistry,
        project: str,
        direction: str = "check",
        axes: Iterable[str] | None = None,
        expected_revision: str | None = None,
    ) -> Job:
        """Commission as a cancellable job (progress events); an unknown project is refused now, not in the job."""
        self.projects.store.open(project)

        def work(progress: Progress, cancel: Cancellation) -> object:
            report = self.commission(project, direction, axes, expected_revision, progress=progress, cancel=cancel)
            return report.as_dict()

        return jobs.start(f"commission-{direction}", work)

    def scan(
        self,
        project: str,
        bus: str,
        bus_name: str | None = None,
        expected_revision: str | None = None,
        create: bool = False,
    ) -> ScanReport:
        return scan_into_project(self.projects, self.connections, project, bus, bus_name, expected_revision, create)

    def select_motor(
        self,
        project: str,
        axis: str,
        reference: str,
        expected_revision: str | None = None,
        buses: Mapping[str, str] | None = None,
    ) -> AxisChoice:
        return select_motor_live(self.projects, project, self.link(project, axis, buses), reference, expected_revision)
