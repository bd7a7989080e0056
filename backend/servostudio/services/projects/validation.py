"""Rules a project must satisfy before it is written: names, buses, devices and node IDs."""

from __future__ import annotations

from collections.abc import Collection

from servostudio.drive.profiles import profile_for
from servostudio.services.projects.errors import ValidationError
from servostudio.services.projects.model import Axis, Project
from servostudio.services.projects.names import check_name, same_name
from servostudio.transport.spec import BusSpecError, parse_bus_spec


def validate_project(project: Project, known_devices: Collection[str]) -> None:
    """Raise :class:`ValidationError` (or ``InvalidName``) naming the first axis or bus that breaks a rule."""
    check_name(project.name, "project")
    _check_unique([bus.name for bus in project.buses], "bus")
    for bus in project.buses:
        check_name(bus.name, "bus")
        try:
            parse_bus_spec(bus.interface)
        except BusSpecError as error:
            raise ValidationError(f"bus '{bus.name}': {error}") from None
        if bus.bitrate is not None and bus.bitrate <= 0:
            raise ValidationError(f"bus '{bus.name}': bit rate must be positive, not {bus.bitrate}")
    _check_unique([axis.name for axis in project.axes], "axis")
    for axis in project.axes:
        _check_axis(axis, project, known_devices)
    for bus in project.buses:
        _check_bus_addresses(bus.name, [axis for axis in project.axes if axis.bus == bus.name])


def _check_unique(names: list[str], what: str) -> None:
    for position, name in enumerate(names):
        for other in names[:position]:
            if same_name(name, other):
                raise ValidationError(f"{what} name '{name}' is used twice (names are compared ignoring case)")


def _check_axis(axis: Axis, project: Project, known_devices: Collection[str]) -> None:
    check_name(axis.name, "axis")
    if axis.device not in known_devices:
        raise ValidationError(
            f"axis '{axis.name}': unknown device '{axis.device}' (known: {', '.join(sorted(known_devices))})"
        )
    if project.bus(axis.bus) is None:
        buses = ", ".join(bus.name for bus in project.buses) or "none defined"
        raise ValidationError(f"axis '{axis.name}': unknown bus '{axis.bus}' (buses: {buses})")
    rules = profile_for(axis.device).addressing
    if axis.node_id not in rules.node_ids:
        raise ValidationError(
            f"axis '{axis.name}': node ID {axis.node_id} is out of range "
            f"{rules.node_ids.start}-{rules.node_ids.stop - 1} ({rules.reason})"
        )


def _check_bus_addresses(bus: str, axes: list[Axis]) -> None:
    """Node IDs are unique per bus, and no axis may sit on a node ID another axis uses as its redirected SDO channel."""
    owner: dict[int, str] = {}
    for axis in axes:
        if axis.node_id in owner:
            raise ValidationError(
                f"axis '{axis.name}': node ID {axis.node_id} on bus '{bus}' is already used by "
                f"axis '{owner[axis.node_id]}'"
            )
        owner[axis.node_id] = axis.name
    for axis in axes:
        offset = profile_for(axis.device).addressing.redirect_offset
        if offset is not None and axis.node_id + offset in owner:
            raise ValidationError(
                f"axis '{owner[axis.node_id + offset]}': node ID {axis.node_id + offset} on bus '{bus}' is reserved by "
                f"axis '{axis.name}' ({axis.device} node {axis.node_id} serves redirected SDO as node "
                f"{axis.node_id + offset})"
            )
