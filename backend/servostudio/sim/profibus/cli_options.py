"""The PROFIBUS part of `servostudio sim`: which listed nodes are TTA-PRO DP slaves, their line, its endpoints and
what the start-up JSON line says about them (docs/profibus.md §6).

`--nodes 5:ttapro --profibus-pty` puts a TTA-PRO at station address 5 on a simulated PROFIBUS line served as a
pseudo-terminal (`"profibus_pty": "/dev/pts/N"`); `--profibus-tcp HOST:PORT` serves it as a raw TCP byte stream
(`"profibus_tcp": "socket://HOST:PORT"`). The CANopen nodes of the list stay on the simulated CAN bus.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from servostudio.od.pnu import builtin_parameter_list
from servostudio.sim.network import NodeSpec, parse_node_list
from servostudio.sim.plant import Plant
from servostudio.sim.profibus import PROFIBUS_DEVICES
from servostudio.sim.profibus.endpoints import ProfibusPty, ProfibusTcpServer
from servostudio.sim.profibus.line import ProfibusLine
from servostudio.sim.profibus.slave import TtaProSlave

STATION_ADDRESSES = range(1, 126)
"""DP station addresses a slave may use: 0 is usually the master, 126 the default address, 127 broadcast."""


@dataclass(frozen=True)
class NodeSplit:
    """The node list cut in two: CANopen nodes for the CAN bus, and the PROFIBUS line (None without ttapro)."""

    can_nodes: list[NodeSpec]
    line: ProfibusLine | None


def split_nodes(args: argparse.Namespace) -> NodeSplit:
    """Raises ValueError for a bad node list, a station address outside 1..125, or endpoint options that do not
    match the nodes (OSError / PlantError for an unreadable plant file)."""
    specs = parse_node_list(args.nodes, args.device)
    slaves = [spec for spec in specs if spec.device in PROFIBUS_DEVICES]
    _check_endpoints(args, slaves)
    if not slaves:
        return NodeSplit(specs, None)
    parameters = builtin_parameter_list()
    line = ProfibusLine([TtaProSlave(spec.node_id, parameters, plant_for(args, spec.node_id)) for spec in slaves])
    return NodeSplit([spec for spec in specs if spec not in slaves], line)


def _check_endpoints(args: argparse.Namespace, slaves: list[NodeSpec]) -> None:
    endpoint = args.profibus_tcp or args.profibus_pty
    if slaves and not endpoint:
        raise ValueError("ttapro nodes are PROFIBUS-DP slaves: give --profibus-pty or --profibus-tcp HOST:PORT")
    if endpoint and not slaves:
        raise ValueError("--profibus-pty / --profibus-tcp need a ttapro node in --nodes (e.g. 5:ttapro)")
    for spec in slaves:
        if spec.node_id not in STATION_ADDRESSES:
            raise ValueError(f"ttapro node {spec.node_id}: a DP station address is 1..125")


def plant_for(args: argparse.Namespace, address: int) -> Plant:
    """The same choice as the CANopen drives': the plant file, else the seed + address, else the default axis."""
    plant_file: Path | None = args.plant
    if plant_file is not None:
        return Plant.from_json(plant_file)
    if args.seed is not None:
        return Plant.from_seed(args.seed + address)
    return Plant.commissioned()


def start_line(
    line: ProfibusLine, args: argparse.Namespace, description: dict[str, object]
) -> list[Callable[[], None]]:
    """Serve the line on its endpoints and run it in real time; returns what stops them, in start order."""
    closers: list[Callable[[], None]] = []
    nodes = description.setdefault("nodes", {})
    if isinstance(nodes, dict):
        nodes.update({str(address): "ttapro" for address in line.slaves})
    if args.profibus_tcp:
        server = ProfibusTcpServer(line, *args.profibus_tcp).start()
        closers.append(server.stop)
        description["profibus_tcp"] = "socket://{}:{}".format(*server.address)
    if args.profibus_pty:
        pty = ProfibusPty(line).start()
        closers.append(pty.stop)
        description["profibus_pty"] = pty.path
    line.start()
    closers.append(line.stop)
    return closers
