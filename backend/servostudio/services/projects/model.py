"""The project file ``project.toml``: what a project is, and its text form.

A project is all the drives of one application connected by CANopen (manual L411-431). The file names the buses and
the axes; each axis's parameter and sequence files live in a directory named after the axis (see ``layout``).
Key order is fixed and axes keep the order in which they were added, so the file diffs cleanly in git.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

from servostudio.services.projects import tomlsubset
from servostudio.services.projects.errors import FileFormatError, ValidationError

FORMAT_VERSION = 1
HEADER_COMMENT = "Servo Studio project file (format 1): see docs/projects.md"


@dataclass(frozen=True)
class Bus:
    """A CAN bus of the project. ``interface`` is a bus spec string (``sim``, ``socketcan:can0``, ``serial:…``)."""

    name: str
    interface: str
    bitrate: int | None = None


@dataclass(frozen=True)
class Axis:
    """One drive: which dictionary (device key), where it sits (bus, node ID), and the choices made for it."""

    name: str
    device: str
    node_id: int
    bus: str
    description: str = ""
    motor: str = ""  # reference of the motor chosen from the catalog ("" = none)
    application: str = ""  # Device Config template key ("" = none chosen)


@dataclass(frozen=True)
class Project:
    name: str
    description: str = ""
    buses: tuple[Bus, ...] = ()
    axes: tuple[Axis, ...] = ()

    def axis(self, name: str) -> Axis | None:
        return next((axis for axis in self.axes if axis.name == name), None)

    def bus(self, name: str) -> Bus | None:
        return next((bus for bus in self.buses if bus.name == name), None)

    def bus_of(self, axis: Axis) -> Bus:
        """The bus an axis is on (the store's rules make sure the project has it)."""
        bus = self.bus(axis.bus)
        if bus is None:
            raise ValidationError(f"axis '{axis.name}' is on bus '{axis.bus}', which project '{self.name}' lacks")
        return bus

    def with_axes(self, axes: tuple[Axis, ...]) -> Project:
        return replace(self, axes=axes)


def to_text(project: Project) -> str:
    document: tomlsubset.Document = {
        ("project",): _table({"format": FORMAT_VERSION, "name": project.name, "description": project.description}),
    }
    for bus in project.buses:
        document[("bus", bus.name)] = _table({"interface": bus.interface, "bitrate": bus.bitrate})
    for axis in project.axes:
        document[("axis", axis.name)] = _table(
            {
                "device": axis.device,
                "node_id": axis.node_id,
                "bus": axis.bus,
                "description": axis.description,
                "motor": axis.motor,
                "application": axis.application,
            }
        )
    return tomlsubset.dump(document, HEADER_COMMENT)


def from_text(text: str, source: Path | str, name: str) -> Project:
    """Parse a project file. ``name`` (the directory name) wins over the ``name`` key, so a copied directory opens."""
    document = tomlsubset.parse(text, source)
    reader = _Reader(source)
    head = document.get(("project",))
    if head is None:
        raise FileFormatError(source, 1, "the [project] table is missing")
    version = reader.get(head, "format", int)
    if version != FORMAT_VERSION:
        raise FileFormatError(source, head.lines["format"], f"format {version} is not supported (expected 1)")
    reader.only(head, {"format", "name", "description"})
    buses: list[Bus] = []
    axes: list[Axis] = []
    for path, table in document.items():
        if path == ("project",):
            continue
        if len(path) == 2 and path[0] == "bus":
            reader.only(table, {"interface", "bitrate"})
            buses.append(Bus(path[1], reader.get(table, "interface", str), reader.get(table, "bitrate", int, None)))
        elif len(path) == 2 and path[0] == "axis":
            reader.only(table, {"device", "node_id", "bus", "description", "motor", "application"})
            axes.append(
                Axis(
                    name=path[1],
                    device=reader.get(table, "device", str),
                    node_id=reader.get(table, "node_id", int),
                    bus=reader.get(table, "bus", str),
                    description=reader.get(table, "description", str, ""),
                    motor=reader.get(table, "motor", str, ""),
                    application=reader.get(table, "application", str, ""),
                )
            )
        else:
            raise FileFormatError(
                source,
                table.line,
                f"unknown table [{tomlsubset.format_path(path)}]; expected [project], [bus.NAME] or [axis.NAME]",
            )
    return Project(name, reader.get(head, "description", str, ""), tuple(buses), tuple(axes))


def _table(values: dict[str, tomlsubset.Value | None]) -> tomlsubset.Table:
    """Empty optional values are left out, so adding e.g. a motor later is a one-line change."""
    return tomlsubset.Table(values={key: value for key, value in values.items() if value is not None and value != ""})


_REQUIRED = object()


@dataclass
class _Reader:
    """Typed access to table values; every error names the file and the line of the offending key."""

    source: Path | str

    def get(self, table: tomlsubset.Table, key: str, kind: type, default: object = _REQUIRED):
        if key not in table.values:
            if default is _REQUIRED:
                raise FileFormatError(self.source, table.line, f"key '{key}' is missing in this table")
            return default
        value = table.values[key]
        if type(value) is not kind:
            expected = {int: "an integer", str: "a quoted string"}[kind]
            raise FileFormatError(self.source, table.lines[key], f"'{key}' must be {expected}, found {value!r}")
        return value

    def only(self, table: tomlsubset.Table, allowed: set[str]) -> None:
        for key, line in table.lines.items():
            if key not in allowed:
                raise FileFormatError(self.source, line, f"unknown key '{key}' (allowed: {', '.join(sorted(allowed))})")
