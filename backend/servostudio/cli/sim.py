"""`servostudio sim`: run simulated drives as a stand-alone server reachable over socketcand and the RS-232 link.

It prints one JSON object describing the endpoints, then runs in real time until SIGINT/SIGTERM.
"""

from __future__ import annotations

import argparse
import json
import signal
import sys
import threading
from pathlib import Path

from servostudio.errors import InvalidInput

DEFAULT_SOCKETCAND = "127.0.0.1:29536"


def host_port(text: str) -> tuple[str, int]:
    """ "HOST:PORT" (port 0 = any free port) for argparse."""
    host, separator, port = text.rpartition(":")
    if not separator or not host or not port.isdigit() or int(port) > 65535:
        raise argparse.ArgumentTypeError(f"expected HOST:PORT, got {text!r}")
    return host, int(port)


def register(commands: argparse._SubParsersAction) -> None:
    sim = commands.add_parser("sim", help="run simulated drives (socketcand server, RS-232 link)")
    sim.add_argument("--nodes", default="1", help='node list, e.g. "1,2,3" or "1:xtrapulspac,2:cd1k" (default: 1)')
    sim.add_argument(
        "--device", default="xtrapulspac", help="device of nodes listed without one (default: xtrapulspac)"
    )
    sim.add_argument(
        "--socketcand",
        type=host_port,
        default=host_port(DEFAULT_SOCKETCAND),
        metavar="HOST:PORT",
        help=f"socketcand endpoint, channel can0 (default: {DEFAULT_SOCKETCAND})",
    )
    sim.add_argument("--channel", default="can0", help="socketcand channel name (default: can0)")
    sim.add_argument(
        "--serial-tcp",
        type=host_port,
        metavar="HOST:PORT",
        help="RS-232 link of the first node as a raw TCP stream (pyserial socket://HOST:PORT)",
    )
    sim.add_argument("--serial-pty", action="store_true", help="RS-232 link of the first node as a pseudo-terminal")
    sim.add_argument(
        "--serial-quirk",
        action="store_true",
        help="reproduce the firmware quirk: SDO responses on the line carry the request identifier",
    )
    sim.add_argument(
        "--profibus-tcp",
        type=host_port,
        metavar="HOST:PORT",
        help="PROFIBUS-DP line of the ttapro nodes as a raw TCP stream (pyserial socket://HOST:PORT)",
    )
    sim.add_argument("--profibus-pty", action="store_true", help="PROFIBUS-DP line of the ttapro nodes as a pty")
    sim.add_argument("--plant", type=Path, metavar="FILE.json", help="hidden plant of every drive (JSON)")
    sim.add_argument("--seed", type=int, help="generate the plants from this seed (+ node ID) instead")
    sim.add_argument(
        "--bitrate",
        type=int,
        default=1_000_000,
        metavar="BPS",
        help="CAN bit rate of the timing model, 0 = frames take no time (default: 1000000)",
    )
    sim.add_argument(
        "--sdo-response-time",
        type=float,
        default=1e-3,
        metavar="SECONDS",
        help="drive-side SDO response time (default: 0.001)",
    )
    sim.add_argument(
        "--state-dir", type=Path, metavar="DIR", help="directory of the drives' flash files (default: in memory)"
    )
    sim.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    from servostudio.sim.network import SimulatedNetwork, drive_behaviour_factory
    from servostudio.sim.profibus.cli_options import split_nodes, start_line
    from servostudio.sim.serial_link import SerialGateway, SerialPty, SerialTcpServer
    from servostudio.sim.socketcand import SocketcandServer

    if args.bitrate < 0:
        raise InvalidInput("--bitrate must be 0 (off) or a positive bit rate")
    try:
        split = split_nodes(args)  # ttapro nodes are PROFIBUS-DP slaves on their own line
        network = None
        if split.can_nodes:
            network = SimulatedNetwork(
                split.can_nodes,
                device=args.device,
                behaviour_factory=drive_behaviour_factory(args.plant, args.seed),
                bitrate=args.bitrate or None,
                sdo_response_time=args.sdo_response_time,
                state_dir=args.state_dir,
            )
    except (ValueError, OSError) as exc:  # bad node list, unknown device, unreadable plant / EDS
        raise InvalidInput(str(exc)) from exc
    stopping = threading.Event()
    closers = []
    try:
        description: dict[str, object] = {"nodes": {}}
        if network is not None:
            host, port = args.socketcand
            socketcand = SocketcandServer(network, host, port, channel=args.channel).start()
            closers.append(socketcand.stop)
            description["nodes"] = {str(node_id): node.store.od.device for node_id, node in network.nodes.items()}
            description["socketcand"] = {
                "host": socketcand.address[0],
                "port": socketcand.address[1],
                "channel": args.channel,
            }
            if args.serial_tcp or args.serial_pty:
                gateway = SerialGateway(network, response_id_quirk=args.serial_quirk)
                closers.append(gateway.close)
                description["serial_node"] = network.first_node.node_id
            if args.serial_tcp:
                serial_tcp = SerialTcpServer(gateway, *args.serial_tcp).start()
                closers.append(serial_tcp.stop)
                description["serial_tcp"] = "socket://{}:{}".format(*serial_tcp.address)
            if args.serial_pty:
                pty = SerialPty(gateway).start()
                closers.append(pty.stop)
                description["serial_pty"] = pty.path
            network.start()
            closers.append(network.stop)
        if split.line is not None:
            closers += start_line(split.line, args, description)
        # the handlers first: a client may stop us as soon as it has read the line below
        for signum in (signal.SIGINT, signal.SIGTERM):
            signal.signal(signum, lambda *_: stopping.set())
        json.dump(description, sys.stdout)
        sys.stdout.write("\n")
        sys.stdout.flush()
        while not stopping.wait(0.5):
            pass
    except OSError as exc:  # an endpoint could not bind
        raise InvalidInput(str(exc)) from exc
    finally:
        for close in reversed(closers):
            close()
    return 0
