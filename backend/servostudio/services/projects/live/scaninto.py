"""Scan into a project (manual §2.3: "If the Project is not defined, use the Scan function"): every identified node
of a bus becomes an axis (name, device, node ID, bus), checked by the store's rules like an axis added by hand.

The bus is a project bus (by name, or by an equal spec) or a new one added with the axes. A node whose identity
matches no dictionary, that an axis of the project already uses, or that a rule refuses (e.g. an XtrapulsPac above
node 63) is reported and left out; the accepted nodes are added in one project change.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, replace

from servostudio.services.bus import ConnectionManager, NodeInfo
from servostudio.services.projects.errors import DriveUnavailable, ProjectError, ValidationError
from servostudio.services.projects.live.links import open_bus
from servostudio.services.projects.model import Axis, Bus, Project
from servostudio.services.projects.names import is_valid_name, same_name
from servostudio.services.projects.service import ProjectService
from servostudio.services.projects.store import Snapshot
from servostudio.services.projects.validation import validate_project
from servostudio.services.scan import scan
from servostudio.transport.spec import BusSpecError, parse_bus_spec

AXIS_PREFIX = "Axis"


@dataclass(frozen=True)
class ScannedNode:
    identity: NodeInfo
    status: str  # added | present | conflict | unknown_device | refused
    axis: str | None = None
    reason: str = ""

    def as_dict(self) -> dict[str, object]:
        return {
            "node_id": self.identity.node,
            "device": self.identity.device,
            "status": self.status,
            "axis": self.axis,
            "reason": self.reason or None,
            "identity": self.identity.as_dict(),
        }


@dataclass(frozen=True)
class ScanReport:
    bus: Bus
    bus_added: bool
    nodes: list[ScannedNode]
    snapshot: Snapshot


def scan_into_project(
    service: ProjectService,
    manager: ConnectionManager,
    project: str,
    bus: str,
    bus_name: str | None = None,
    expected_revision: str | None = None,
    create: bool = False,
) -> ScanReport:
    """Scan ``bus`` (a project bus name or a bus spec) and add an axis for every new identified node; with
    ``create`` a project that does not exist yet is created first (the manual's "project not defined" case)."""
    if create and not any(same_name(name, project) for name in service.store.names()):
        service.store.create(project)
    snapshot = service.store.open(project)
    chosen, added = _choose_bus(snapshot.project, bus, bus_name)
    connection = open_bus(manager, chosen, chosen.interface)
    if not connection.link.connected:
        raise DriveUnavailable(
            f"bus '{chosen.name}' ({chosen.interface}) is not connected: "
            f"{connection.link.last_error or 'no connection'}"
        )
    found = scan(connection)
    candidate = replace(snapshot.project, buses=(*snapshot.project.buses, chosen)) if added else snapshot.project
    nodes, new_axes = [], []
    for info in found:
        result = _place(candidate, chosen, info, service.library.devices())
        nodes.append(result)
        if result.status == "added" and result.axis is not None and info.device is not None:
            axis = Axis(result.axis, info.device, info.node, chosen.name)
            candidate = candidate.with_axes((*candidate.axes, axis))
            new_axes.append(axis)
    if new_axes or added:
        snapshot = service.store.add_axes(
            project, tuple(new_axes), expected_revision or snapshot.revision, buses=(chosen,) if added else ()
        )
    return ScanReport(chosen, added, nodes, snapshot)


def _choose_bus(project: Project, text: str, new_name: str | None) -> tuple[Bus, bool]:
    """A project bus named ``text`` or with the same spec, else a new bus (``new_name`` or derived from the spec)."""
    named = project.bus(text)
    if named is not None:
        return named, False
    try:
        spec = parse_bus_spec(text)
    except BusSpecError as error:
        buses = ", ".join(bus.name for bus in project.buses) or "none"
        raise ValidationError(
            f"'{text}' is neither a bus of project '{project.name}' ({buses}) nor a bus spec: {error}"
        ) from None
    for existing in project.buses:
        if parse_bus_spec(existing.interface) == spec:
            return existing, False
    return Bus(new_name or bus_name_for(text, project), text.strip()), True


def bus_name_for(spec: str, project: Project) -> str:
    """A valid, unused bus name from the spec text ("socketcan:can0" -> "socketcan-can0", then "…-2", "…-3")."""
    cleaned = re.sub(r"^[^A-Za-z0-9]+", "", re.sub(r"[^A-Za-z0-9_.+-]+", "-", spec))[:56].rstrip(" .")
    base = cleaned if is_valid_name(cleaned) else "bus"
    name, number = base, 2
    while any(same_name(bus.name, name) for bus in project.buses):
        name, number = f"{base}-{number}", number + 1
    return name


def _place(project: Project, bus: Bus, info: NodeInfo, devices: list[str]) -> ScannedNode:
    present = next((axis for axis in project.axes if axis.bus == bus.name and axis.node_id == info.node), None)
    if present is not None:
        if present.device == info.device:
            return ScannedNode(info, "present", present.name)
        return ScannedNode(
            info,
            "conflict",
            present.name,
            f"axis '{present.name}' expects device '{present.device}', the node is {info.device or 'unidentified'}",
        )
    if info.device is None or info.device not in devices:
        return ScannedNode(
            info,
            "unknown_device",
            None,
            f"vendor 0x{info.vendor_id or 0:X}, product "
            f"0x{info.product_code or 0:X} match no dictionary of the EDS library",
        )
    name = _axis_name(project, info.node, bus)
    try:
        validate_project(project.with_axes((*project.axes, Axis(name, info.device, info.node, bus.name))), devices)
    except ProjectError as error:
        return ScannedNode(info, "refused", None, str(error))
    return ScannedNode(info, "added", name)


def _axis_name(project: Project, node: int, bus: Bus) -> str:
    for name in (f"{AXIS_PREFIX}{node}", f"{AXIS_PREFIX}{node}-{bus.name}"[:64]):
        if not any(same_name(axis.name, name) for axis in project.axes):
            return name
    number = 2
    while any(same_name(axis.name, f"{AXIS_PREFIX}{node}-{number}") for axis in project.axes):
        number += 1
    return f"{AXIS_PREFIX}{node}-{number}"
