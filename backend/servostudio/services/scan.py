"""Scan: find every node of a bus in well under a second and identify it.

All nodes are probed at once (an SDO read of 0x1000 per node, short timeout, no abort to silent nodes, a second
round for the silent ones); the
responders are then identified in parallel (0x1018 identity, 0x1008/0x1009/0x100A names and versions) and matched
to a device dictionary of the EDS library.  A serial link only reaches nodes 1–63 (the redirection range).
XtrapulsPac drives also answer on 0x600+(n+64), their redirected channel; such an echo of node n is not
reported as node n+64.

A PROFIBUS-DP line (a TTA-PRO) has no SDO: its stations are found by Slave_Diag on 3..125 (0..2 are the masters'
addresses by convention; the master's own is skipped), and each ident number is matched to a parameter list of
the library (vendor ID 0, product code = ident number). The nodes are the station addresses, and the result has
the same shape as on a CANopen bus (docs/profibus.md §9).
"""

from __future__ import annotations

from concurrent.futures import Future
from typing import Any

from servostudio.drive.profibus.link import ProfibusLink
from servostudio.drive.sdo import SdoAbortError, SdoError, SdoLinkError, settle
from servostudio.errors import CommunicationError, NotFound, Timeout, Unavailable
from servostudio.od.datatypes import DataType, decode
from servostudio.services.bus.connections import BusConnection, NodeInfo
from servostudio.transport.profibus.dp_services import SlaveDiag
from servostudio.transport.profibus.scan import scan as scan_line

PROBE_TIMEOUT = 0.15
PROBE_ROUNDS = 2
REDIRECT_OFFSET = 64
SERIAL_PROBE_TIMEOUT = 0.4
DP_STATIONS = range(3, 126)
_IDENTITY = {
    "vendor_id": (0x1018, 1, DataType.UNSIGNED32),
    "product_code": (0x1018, 2, DataType.UNSIGNED32),
    "revision": (0x1018, 3, DataType.UNSIGNED32),
    "serial_number": (0x1018, 4, DataType.UNSIGNED32),
    "device_name": (0x1008, 0, DataType.VISIBLE_STRING),
    "hardware_version": (0x1009, 0, DataType.VISIBLE_STRING),
    "software_version": (0x100A, 0, DataType.VISIBLE_STRING),
}


class NoAnswer(Timeout):
    """No node answered on the bus, or not the node asked for."""


class UnknownDevice(NotFound):
    """The node identified itself as a device no dictionary of the EDS library describes."""


class ScanInterrupted(Unavailable):
    """The bus went down or was closed during the scan; what the scan knew before is kept."""


class NothingFound(NotFound):
    """A scan found no node (the CLI's answer: an empty bus is not what a user scans for); the message says why
    that may be on this kind of bus."""


#: why a bus may look empty, by kind; every CAN bus also gets ``_CAN_REASONS``
_EMPTY_REASONS = {
    "virtual": "a virtual channel reaches only the buses this process opened on it, so drives simulated by another "
    "process are not there (reach them with socketcand: servostudio sim --socketcand HOST:PORT)",
    "sim": "the simulated bus was opened without nodes (name them: sim:1,2,3)",
    "serial": "check the RS-232 cable and its baud rate (the drive's 0x2300, 19200 by default), and that the drive "
    "on the link is powered; the link reaches nodes 1-63 through it",
    "socketcand": "the socketcand server's channel (socketcand:HOST:PORT/CHANNEL, can0 by default) may be another "
    "one than the drives'",
    "profibus": "no DP station answered Slave_Diag on 3-125: check the RS-485 line (termination at both ends, "
    "A/B not swapped), that its baud rate is the line's, that the drives are powered and their station addresses "
    "set, and that no other master holds them",
}
_CAN_REASONS = (
    "the drives are not powered (logic supply), the bit rate differs from the drives' (every node and the "
    "adapter must use the same), the bus lacks its 120 ohm termination at both ends, or no node ID is set"
)


def empty_scan_hint(connection: BusConnection) -> str:
    """Why a scan of this bus found no node: the likely reasons for its kind of bus."""
    kind = connection.spec.kind
    reasons = [_EMPTY_REASONS[kind]] if kind in _EMPTY_REASONS else []
    if kind not in ("sim", "serial", "virtual", "profibus"):
        reasons.append(_CAN_REASONS)
    return f"no node answered on {connection.spec}: " + "; or ".join(reasons)


def scan(connection: BusConnection, nodes: range | list[int] | None = None) -> list[NodeInfo]:
    """Probe, identify and remember the nodes present among ``nodes`` (default: every node ID).

    A bus lost or closed meanwhile ends the scan with `ScanInterrupted` at once: silence on a dead link says
    nothing about the nodes, so the nodes known before are kept."""
    try:
        if isinstance(connection.link, ProfibusLink):
            return _scan_profibus(connection, connection.link, nodes)
        return _scan(connection, nodes)
    except SdoLinkError as error:
        raise ScanInterrupted(f"scan of bus {connection.id} stopped: {error.reason}") from None
    except Unavailable as error:  # the DP line failed
        raise ScanInterrupted(f"scan of bus {connection.id} stopped: {error}") from None


def _scan(connection: BusConnection, nodes: range | list[int] | None) -> list[NodeInfo]:
    serial = connection.spec.kind == "serial"
    candidates = list(nodes) if nodes is not None else list(range(1, 64 if serial else 128))
    timeout = SERIAL_PROBE_TIMEOUT if serial else PROBE_TIMEOUT
    engine = connection.engine
    present: dict[int, object] = {}
    for _ in range(PROBE_ROUNDS):  # a second round catches a node whose first answer was lost or late
        probes = {
            node: engine.upload(node, 0x1000, 0, timeout=timeout, probe=True)
            for node in candidates
            if node not in present
        }
        present.update(
            {node: _value(future, DataType.UNSIGNED32) for node, future in probes.items() if _answered(future)}
        )
    for node in [node for node in present if node > REDIRECT_OFFSET and node - REDIRECT_OFFSET in present]:
        del present[node]  # 0x600+(n+64) is node n's redirected SDO channel, not another node
    found = [_identify(connection, node, device_type) for node, device_type in sorted(present.items())]
    return _remember(connection, candidates, found, everything=nodes is None)


def _remember(
    connection: BusConnection, candidates: list[int], found: list[NodeInfo], everything: bool
) -> list[NodeInfo]:
    """Keep what the scan found (of every node, or of the candidates only) and tell the subscribers."""
    if everything:
        connection.nodes = {}
    for node in candidates:
        connection.nodes.pop(node, None)
    connection.nodes.update({info.node: info for info in found})
    hint = None if found else empty_scan_hint(connection)
    identities = [info.as_dict() for info in found]
    connection.events.publish({"type": "scan", "bus": connection.id, "nodes": identities, "hint": hint})
    return found


def _scan_profibus(connection: BusConnection, link: ProfibusLink, nodes: range | list[int] | None) -> list[NodeInfo]:
    """Slave_Diag on every candidate station; each answer's ident number names its device."""
    own = connection.spec.profibus_master
    candidates = [node for node in (nodes if nodes is not None else DP_STATIONS) if node != own]
    stations: dict[int, SlaveDiag] = {}
    for _ in range(PROBE_ROUNDS):  # as on CAN: a second round catches a station whose first answer was late
        stations.update(scan_line(link.master, [node for node in candidates if node not in stations]))
    found = [_dp_node(connection, address, diag.ident_number) for address, diag in sorted(stations.items())]
    return _remember(connection, candidates, found, everything=nodes is None)


def _dp_node(connection: BusConnection, address: int, ident_number: int) -> NodeInfo:
    device = connection.library.match(0, ident_number)
    name = connection.library.load(device).product_name if device else None
    return NodeInfo(node=address, device=device, vendor_id=0, product_code=ident_number, device_name=name)


def _identify_station(connection: BusConnection, link: ProfibusLink, node: int) -> NodeInfo | None:
    try:
        diag = link.master.slave_diag(node)
    except (Timeout, CommunicationError):  # no answer, or not a DP slave's answer
        return None
    info = _dp_node(connection, node, diag.ident_number)
    connection.nodes[node] = info
    return info


def identify(connection: BusConnection, node: int) -> NodeInfo | None:
    """Identify one node (or None if it does not answer) and remember it."""
    if isinstance(connection.link, ProfibusLink):
        return _identify_station(connection, connection.link, node)
    for _ in range(PROBE_ROUNDS):
        probe = connection.engine.upload(node, 0x1000, 0, probe=True)
        if _answered(probe):
            break
    else:
        return None
    info = _identify(connection, node, _value(probe, DataType.UNSIGNED32))
    connection.nodes[node] = info
    return info


def identified(connection: BusConnection, node: int) -> NodeInfo:
    """Identify a node that must answer and be a device of the library (the node a command names)."""
    info = identify(connection, node)
    if info is None:
        raise NoAnswer(f"node {node} does not answer on {connection.spec}")
    if info.device is None:
        raise UnknownDevice(
            f"node {node} (vendor 0x{info.vendor_id or 0:X}, product 0x{info.product_code or 0:X}) "
            "matches no dictionary of the EDS library; name its device"
        )
    return info


def _identify(connection: BusConnection, node: int, device_type: object) -> NodeInfo:
    requests = {
        name: (connection.engine.upload(node, index, sub), data_type)
        for name, (index, sub, data_type) in _IDENTITY.items()
    }
    values: dict[str, Any] = {name: _value(future, data_type) for name, (future, data_type) in requests.items()}
    info = NodeInfo(node=node, device_type=device_type if isinstance(device_type, int) else None, **values)
    if info.vendor_id is not None:
        info.device = connection.library.match(info.vendor_id, info.product_code or 0)
    cob_id = _statusword_pdo(connection, node)
    if cob_id is not None and connection.monitor is not None:
        connection.monitor.watch_statusword(node, cob_id)
    return info


def _statusword_pdo(connection: BusConnection, node: int) -> int | None:
    """COB-ID of a valid TPDO whose first mapped object is the status word 0x6041 (None if there is none)."""
    engine = connection.engine
    requests = [(engine.upload(node, 0x1800 + pdo, 1), engine.upload(node, 0x1A00 + pdo, 1)) for pdo in range(4)]
    for communication, mapping in requests:
        cob_id, first = _value(communication, DataType.UNSIGNED32), _value(mapping, DataType.UNSIGNED32)
        if isinstance(cob_id, int) and isinstance(first, int) and first >> 16 == 0x6041 and not cob_id & 0x80000000:
            return cob_id & 0x7FF
    return None


def _answered(future: Future) -> bool:
    """A node is present when it answered at all — an abort is an answer too; a dead link answers nothing (raised)."""
    try:
        settle(future)
    except SdoLinkError:
        raise
    except SdoAbortError:
        return True
    except SdoError:
        return False
    return True


def _value(future: Future, data_type: DataType) -> int | float | str | bytes | None:
    try:
        raw = settle(future)
    except SdoLinkError:
        raise
    except SdoError:
        return None
    size = data_type.size
    try:
        value = decode(data_type, raw[:size] if size else raw)
    except ValueError:
        return None
    return value.rstrip("\0") if isinstance(value, str) else value
