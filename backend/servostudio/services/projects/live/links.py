"""Reach the drives of a project: open its buses through the server's ConnectionManager and check every axis.

An axis is usable when its bus is connected, its node answers and identifies itself (0x1018 vendor/product, matched
to a dictionary of the EDS library) as the axis's device. A drive of another type on the node is never written:
its dictionary would give other meanings to the same objects. Axes are identified in parallel.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

from servostudio.drive.access import Drive
from servostudio.services.bus import BusConnection, ConnectionManager, NodeInfo
from servostudio.services.projects.errors import DriveMismatch, DriveUnavailable, ProjectNotFound
from servostudio.services.projects.model import Axis, Bus, Project
from servostudio.services.scan import identify

CONNECT_WAIT = 3.0


@dataclass(frozen=True)
class AxisLink:
    """An axis and what was found at its address; ``status`` is ok, bus_down, no_answer or wrong_device."""

    axis: Axis
    bus: Bus
    spec: str
    connection: BusConnection | None
    identity: NodeInfo | None
    status: str
    problem: str = ""

    @property
    def ok(self) -> bool:
        return self.status == "ok"

    def drive(self) -> Drive:
        """Drive access with the axis's dictionary; raises when the axis is not usable."""
        if self.status == "wrong_device":
            raise DriveMismatch(self.problem)
        if not self.ok or self.connection is None:
            raise DriveUnavailable(self.problem)
        return self.connection.drive(self.axis.node_id, self.axis.device)

    def as_dict(self) -> dict[str, object]:
        return {
            "axis": self.axis.name,
            "device": self.axis.device,
            "node_id": self.axis.node_id,
            "bus": self.bus.name,
            "spec": self.spec,
            "bus_id": self.connection.id if self.connection is not None else None,
            "status": self.status,
            "problem": self.problem or None,
            "identity": self.identity.as_dict() if self.identity is not None else None,
        }


def select_axes(project: Project, names: Iterable[str] | None) -> list[Axis]:
    """The named axes (all when ``names`` is None), in project order; an unknown name is refused."""
    if names is None:
        return list(project.axes)
    wanted = list(names)
    unknown = [name for name in wanted if project.axis(name) is None]
    if unknown:
        known = ", ".join(axis.name for axis in project.axes) or "none"
        raise ProjectNotFound(f"project '{project.name}' has no axis {', '.join(map(repr, unknown))} (axes: {known})")
    return [axis for axis in project.axes if axis.name in wanted]


def open_bus(manager: ConnectionManager, bus: Bus, spec: str, wait: float = CONNECT_WAIT) -> BusConnection:
    """The server's connection for a project bus (an open bus with the same spec is shared). A shared bus may still
    be connecting (the server opens its startup buses without waiting): it gets the same ``wait``."""
    taken = {connection.id for connection in manager.list()}
    connection = manager.open(spec, bus.name if bus.name not in taken else None, wait=wait)
    if not connection.link.connected:
        connection.link.wait_connected(wait)
    return connection


def link_axes(
    project: Project,
    manager: ConnectionManager,
    names: Iterable[str] | None = None,
    buses: Mapping[str, str] | None = None,
) -> list[AxisLink]:
    """Connect the buses of the chosen axes and identify each axis's node. ``buses`` maps a project bus name to
    another spec to use for this session (e.g. the project says ``sim``, the drives are behind socketcand)."""
    axes = select_axes(project, names)
    overrides = dict(buses or {})
    unknown = set(overrides) - {bus.name for bus in project.buses}
    if unknown:
        raise ProjectNotFound(f"project '{project.name}' has no bus {', '.join(sorted(unknown))}")
    connections: dict[str, tuple[str, BusConnection]] = {}
    for axis in axes:
        bus = project.bus_of(axis)
        if bus.name not in connections:
            spec = overrides.get(bus.name, bus.interface)
            connections[bus.name] = (spec, open_bus(manager, bus, spec))
    with ThreadPoolExecutor(max_workers=max(1, len(axes)), thread_name_prefix="identify") as pool:
        return list(pool.map(lambda axis: _link(project.bus_of(axis), axis, *connections[axis.bus]), axes))


def link_axis(
    project: Project, manager: ConnectionManager, axis: str, buses: Mapping[str, str] | None = None
) -> AxisLink:
    return link_axes(project, manager, [axis], buses)[0]


def _link(bus: Bus, axis: Axis, spec: str, connection: BusConnection) -> AxisLink:
    where = f"axis '{axis.name}' (node {axis.node_id} on bus '{bus.name}', {spec})"
    if not connection.link.connected:
        reason = connection.link.last_error or "no connection"
        return AxisLink(axis, bus, spec, connection, None, "bus_down", f"{where}: bus not connected ({reason})")
    info = identify(connection, axis.node_id)
    if info is None:
        return AxisLink(axis, bus, spec, connection, None, "no_answer", f"{where}: the node does not answer")
    if info.device != axis.device:
        found = f"device '{info.device}'" if info.device else "a device no dictionary of the EDS library matches"
        return AxisLink(
            axis,
            bus,
            spec,
            connection,
            info,
            "wrong_device",
            f"{where}: expected device '{axis.device}', found {found} (vendor 0x{info.vendor_id or 0:X}, "
            f"product 0x{info.product_code or 0:X}); nothing is written to it",
        )
    return AxisLink(axis, bus, spec, connection, info, "ok")
