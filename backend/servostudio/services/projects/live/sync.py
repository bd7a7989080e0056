"""Drive ↔ project, object by object: compare, take the drive's values into the project, write the project's values
to the drive.

Taking values goes through ``ParameterService.set`` (the offline checks; all or nothing). Writing checks every value
exactly like an online write (``Drive.prepare_write``: access, type, range) before the first frame is sent: one bad
value refuses the whole selection. The writes are then queued in order (the drive applies them in that order, so
side effects of a later write win as they would by hand) and every object is read back afterwards.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

from servostudio.drive.access import DEFAULT_WAIT, DriveAccessError
from servostudio.drive.sdo import SdoAbortError
from servostudio.od import Variable
from servostudio.services.projects.compare import CompareRow
from servostudio.services.projects.errors import ParameterRefused
from servostudio.services.projects.live.links import AxisLink
from servostudio.services.projects.live.source import DriveValues
from servostudio.services.projects.parameter_values import Value, display
from servostudio.services.projects.parameters import ParameterChange, ParameterService


def address_of(variable: Variable) -> str:
    return f"0x{variable.index:04X},{variable.subindex}"


@dataclass(frozen=True)
class LiveCompare:
    rows: list[CompareRow]
    revision: str
    refused: dict[str, str]  # objects the drive refused to read: address -> reason
    read_only: list[CompareRow] = field(default_factory=list)  # asked for: read-only entries, not counted


def compare_with_drive(
    parameters: ParameterService,
    project: str,
    link: AxisLink,
    *,
    group: str | None = None,
    only_differences: bool = False,
    read_only: bool = False,
) -> LiveCompare:
    """Columns drive / project / default; all drive reads are queued at once. With ``read_only`` the read-only
    entries are read too and given apart (they are never counted as differences: nobody can write them)."""
    axis = link.axis.name
    variables = parameters.transferable(project, axis, group)
    if read_only:
        variables += parameters.read_only_variables(project, axis, group)
    source = DriveValues(link.drive(), variables)
    rows, revision = parameters.compare(project, axis, group=group, only_differences=only_differences, drive=source)
    apart = parameters.read_only(project, axis, group=group, drive=source) if read_only else []
    refused = {f"0x{index:04X},{sub}": reason for (index, sub), reason in source.refused.items()}
    return LiveCompare(rows, revision, refused, apart)


def take_from_drive(
    parameters: ParameterService,
    project: str,
    link: AxisLink,
    addresses: Sequence[str] | None,
    expected_revision: str | None = None,
) -> ParameterChange:
    """Store the drive's values of the given objects (None: every object whose drive value differs) in the project;
    any refusal leaves the project unchanged."""
    axis = link.axis.name
    if addresses is None:
        compared = compare_with_drive(parameters, project, link, only_differences=True)
        chosen = {row.variable: row.values["drive"] for row in compared.rows}
        refused = compared.refused
        if not chosen:
            return ParameterChange([], compared.revision)
    else:
        variables = _resolve(parameters, project, axis, addresses)
        source = DriveValues(link.drive(), variables)
        chosen = {variable: source.read(*variable.key) for variable in variables}
        refused = {address_of(v): reason for v in variables if (reason := source.refused.get(v.key))}
    missing = [variable for variable, value in chosen.items() if value is None]
    if missing:
        reasons = "; ".join(f"{v.label}: {refused.get(address_of(v), 'no value')}" for v in missing[:5])
        raise ParameterRefused(f"the drive gave no value for {len(missing)} object(s) ({reasons}); nothing was taken")
    changes = {address_of(v): value for v, value in chosen.items()}
    return parameters.set(project, axis, changes, expected_revision, keep=f"drive values of axis {axis} taken")


@dataclass
class DriveWrite:
    variable: Variable
    value: Value
    status: str = "not written"  # written | failed | not written
    error: str = ""
    read_back: Value | None = None

    def as_dict(self) -> dict[str, object]:
        return {
            "address": address_of(self.variable),
            "name": self.variable.label,
            "value": display(self.variable, self.value),
            "status": self.status,
            "error": self.error or None,
            "drive": display(self.variable, self.read_back),
        }


@dataclass
class DriveWriteReport:
    axis: str
    writes: list[DriveWrite] = field(default_factory=list)
    stored: bool = False

    @property
    def ok(self) -> bool:
        return all(write.status == "written" for write in self.writes)

    def as_dict(self) -> dict[str, object]:
        return {
            "axis": self.axis,
            "ok": self.ok,
            "stored": self.stored,
            "objects": [write.as_dict() for write in self.writes],
        }


def write_to_drive(
    parameters: ParameterService, project: str, link: AxisLink, addresses: Sequence[str] | None, store: bool = False
) -> DriveWriteReport:
    """Write the project's values of the given objects (None: every object whose drive value differs) to the drive;
    with ``store`` the drive then saves its parameters to flash (the profile's 'save' procedure)."""
    axis = link.axis.name
    drive = link.drive()
    if addresses is None:
        rows = compare_with_drive(parameters, project, link, only_differences=True).rows
        chosen = [(row.variable, row.values["project"]) for row in rows]
    else:
        chosen = []
        for address in addresses:
            row, _revision = parameters.get(project, axis, address)
            chosen.append((row.variable, row.value))
    writes = [DriveWrite(variable, _project_value(variable, value)) for variable, value in chosen]
    for write in writes:  # everything is checked before the first frame is sent
        try:
            drive.prepare_write(write.variable, write.value)
        except DriveAccessError as error:
            raise ParameterRefused(f"{error}; nothing was written") from None
    batch = drive.submit_write_all([(write.variable, write.value) for write in writes])
    for write, outcome in zip(writes, batch.future.result(DEFAULT_WAIT), strict=True):
        if isinstance(outcome, SdoAbortError):
            write.status, write.error = "failed", outcome.reason
        elif isinstance(outcome, Exception):  # no answer: the first such write ended the batch
            raise outcome
        else:
            write.status = "written"
    report = DriveWriteReport(axis, writes)
    after = DriveValues(drive, [write.variable for write in writes])
    for write in writes:
        write.read_back = after.read(*write.variable.key)
    if store and writes and report.ok:
        drive.start_procedure("save")
        report.stored = True
    return report


def _resolve(parameters: ParameterService, project: str, axis: str, addresses: Sequence[str]) -> list[Variable]:
    if not addresses:
        raise ParameterRefused("no object given")
    return [parameters.get(project, axis, address)[0].variable for address in addresses]


def _project_value(variable: Variable, value: Value | None) -> Value:
    if value is None:
        raise ParameterRefused(
            f"{variable.label}: the project has no value for it (no default, not set); nothing was written"
        )
    return value
