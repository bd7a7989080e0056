"""Drive commands: ``servostudio scan|read|write|backup|restore|store|nmt|fault|state|io --bus SPEC [--node N] …``.

Through a running server (``--server URL``, ``$SERVOSTUDIO_SERVER`` or the config file: ``cli.remote``) each
command is the server's REST calls (``cli.server_drive``); with ``--bus`` alone it opens the bus itself (headless).
Here each command opens the bus, does its work, prints JSON on stdout and exits with the code of what went wrong
(the kind of the error, see ``servostudio.cli.output``): 3 refused (nothing written), 4 unknown node/object or a
scan that found no node, 5 communication.
"""

from __future__ import annotations

import argparse
import signal
import sys
import threading
from collections.abc import Callable, Sequence
from pathlib import Path

from servostudio.cli import io_changes, remote, server_drive
from servostudio.cli.audit import audit_log, guarded_connections, local_actor
from servostudio.cli.output import emit
from servostudio.drive.access import Drive
from servostudio.drive.cia402 import State
from servostudio.drive.control import fault_report, read_state, reset_faults, set_state
from servostudio.drive.link import LinkDownError
from servostudio.errors import InvalidInput
from servostudio.services import io
from servostudio.services.audit import acting_as
from servostudio.services.backup import (
    BackupError,
    RestoreResult,
    backup_drive,
    backup_file,
    restore_drive,
    restore_file,
    run_per_drive,
    store_parameters,
)
from servostudio.services.bus import BusConnection
from servostudio.services.motion import Axis, MotionGuard
from servostudio.services.scan import NothingFound, empty_scan_hint, identified, scan
from servostudio.services.transfers import FileResult, per_node

CONNECT_WAIT = 3.0


Handler = Callable[[argparse.Namespace, BusConnection], object]
ServerHandler = Callable[[argparse.Namespace, server_drive.ServerBus], object]


def register(commands: argparse._SubParsersAction) -> None:
    def add(
        name: str, help_text: str, handler: Handler, through_server: ServerHandler, node: str = "one"
    ) -> argparse.ArgumentParser:
        parser = commands.add_parser(name, help=help_text)
        parser.add_argument(
            "--bus",
            metavar="SPEC",
            help="the bus to open here, e.g. socketcand:127.0.0.1:29536, serial:/dev/ttyUSB0@19200, socketcan:can0, "
            "sim; with --server the server's bus (name or spec; default: its only bus)",
        )
        remote.add_options(parser, suppress=True)
        if node == "one":
            parser.add_argument("--node", type=int, required=True, help="node ID 1..127")
            parser.add_argument("--device", help="device key when the node does not identify itself")
        elif node == "many":
            parser.add_argument("--node", type=int, action="append", help="node ID, repeatable (default: scan)")
            parser.add_argument("--device", help="device key of the given nodes when they do not identify themselves")
        parser.set_defaults(handler=lambda args: _run(args, parser, handler, through_server))
        return parser

    add("scan", "find and identify the nodes of a bus", _scan, server_drive.scan, node="none")
    read = add("read", "read objects of a node", _read, server_drive.read)
    read.add_argument("objects", nargs="+", metavar="OBJECT", help="0x6041, 0x60F9,2, a name, or statusword")
    write = add("write", "write an object of a node (checked before anything is sent)", _write, server_drive.write)
    write.add_argument("object", metavar="OBJECT")
    write.add_argument("value", metavar="VALUE", help="number, 0x hex, enumeration label or text")
    write.add_argument("--physical", action="store_true", help="VALUE is in the object's unit")
    backup = add(
        "backup",
        "back up drive files (DRIVEPAR.TXT, USER_PAR.TXT, SEQUENCE.TXT)",
        _backup,
        server_drive.backup,
        node="many",
    )
    backup.add_argument(
        "--out",
        type=Path,
        required=True,
        help="file (one node: kind from its name) or directory (DIR/node<N>/ per node)",
    )
    restore = add(
        "restore", "validate, write, verify and store drive files", _restore, server_drive.restore, node="many"
    )
    restore.add_argument("--in", dest="source", type=Path, required=True, help="file (one node) or directory")
    restore.add_argument("--no-store", action="store_true", help="do not store to flash afterwards")
    add(
        "store",
        "store the drive's parameters in its non-volatile memory (the device's save: 0x1010,1 = 'save', a TTA-PRO's "
        "PNU 729 = 1)",
        _store,
        server_drive.store,
    )
    nmt = add("nmt", "send an NMT command", _nmt, server_drive.nmt, node="none")
    nmt.add_argument(
        "command_name", metavar="COMMAND", help="start, stop, pre-operational, reset-node, reset-communication"
    )
    nmt.add_argument("--node", type=int, default=0, help="node ID (default 0: all nodes)")
    fault = add("fault", "show active faults with the manual's remedy; --reset resets them", _fault, server_drive.fault)
    fault.add_argument("--reset", action="store_true")
    state = add(
        "state",
        "show the CiA 402 state, or walk to TARGET (operation-enabled holds the axis enabled "
        "until the command is interrupted, then quick-stops it)",
        _state,
        server_drive.state,
    )
    state.add_argument(
        "target",
        nargs="?",
        help="switch-on-disabled, ready-to-switch-on, switched-on, operation-enabled, quick-stop-active",
    )
    io_command = add(
        "io",
        "show the I/O configuration, its live state and the fail-safe findings; --input/--output/--set change it "
        "(the whole change checked before anything is written)",
        _io,
        server_drive.io,
    )
    io_command.add_argument(
        "--input",
        dest="inputs",
        action="append",
        default=[],
        metavar="NAME=FUNCTION[:inverted|:normal]",
        help="a logic input's function / polarity",
    )
    io_command.add_argument(
        "--output",
        dest="outputs",
        action="append",
        default=[],
        metavar="NAME=FUNCTION[:inverted|:normal]",
        help="an output's function / polarity",
    )
    io_command.add_argument("--set", dest="settings", action="append", default=[], metavar="KEY=VALUE",
                            help="an I/O setting (analog scaling, encoder emulation …)")  # fmt: skip
    share = add(
        "share",
        "share a bus of the running server as a socketcand endpoint for your own CANopen scripts (loopback only)",
        _share_here,
        server_drive.share,
        node="none",
    )
    share.add_argument("--port", type=int, default=0, help="TCP port (default 0: any free port, printed)")
    share.add_argument("--host", default="127.0.0.1", help="loopback address to bind (default 127.0.0.1)")
    share.add_argument("--off", action="store_true", help="stop sharing the bus")


def _run(
    args: argparse.Namespace, parser: argparse.ArgumentParser, handler: Handler, through_server: ServerHandler
) -> int:
    """Through the server the command names (``--server``, or the default of ``cli.remote``), or on the bus it
    names (``--bus``, headless)."""
    server = remote.Remote.of(args)
    if server is not None:
        return emit(through_server(args, server_drive.ServerBus.of(server, args)))
    if args.bus is None:
        parser.error(f"--bus SPEC is needed (or --server URL, ${remote.SERVER_VARIABLE}, or a config file)")
    return _run_here(args, handler)


def _run_here(args: argparse.Namespace, handler: Handler) -> int:
    """Open the bus, run the command on it as the person at the terminal (through the motion guard, recorded in
    the audit log), close it; errors go to ``main``, which exits with their kind's code."""
    manager = guarded_connections(audit_log())
    args.motion = manager.motion
    try:
        with acting_as(local_actor()):
            connection = manager.open(args.bus, wait=CONNECT_WAIT)
            if not connection.link.connected:
                raise LinkDownError(f"bus {args.bus}: not connected ({connection.link.last_error or 'no answer'})")
            return emit(handler(args, connection))
    finally:
        manager.close_all()


class ShareNeedsServer(InvalidInput):
    """``share`` shares a bus of a running server; this process would stop sharing when it ends."""


def _share_here(args: argparse.Namespace, connection: BusConnection) -> object:
    raise ShareNeedsServer("share works on a running server's bus: give --server URL (or start the server with "
                           "servostudio serve --share BUS=PORT)")  # fmt: skip


def _drive(args: argparse.Namespace, connection: BusConnection, node: int | None = None) -> Drive:
    """The node's drive; a node named without ``--device`` must answer and be a device of the library."""
    node = node if node is not None else args.node
    device = getattr(args, "device", None)
    if device is None:
        identified(connection, node)
    return connection.drive(node, device)


def _nodes(args: argparse.Namespace, connection: BusConnection) -> list[Drive]:
    if args.node:
        return [_drive(args, connection, node) for node in args.node]
    found = scan(connection)
    if not found:
        raise NothingFound(empty_scan_hint(connection))
    return [connection.drive(info.node) for info in found if info.device]


def _scan(args: argparse.Namespace, connection: BusConnection) -> object:
    """The nodes found; finding none is a failure here (exit 4, the reasons on stderr), after printing the empty
    list for scripts that read stdout."""
    found = [info.as_dict() for info in scan(connection)]
    if not found:
        emit(found)
        raise NothingFound(empty_scan_hint(connection))
    return found


def _read(args: argparse.Namespace, connection: BusConnection) -> object:
    drive = _drive(args, connection)
    values = [drive.read(key).as_dict() for key in args.objects]
    return values[0] if len(values) == 1 else values


def _write(args: argparse.Namespace, connection: BusConnection) -> object:
    return _drive(args, connection).write(args.object, args.value, args.physical).as_dict()


def _backup(args: argparse.Namespace, connection: BusConnection) -> object:
    drives = _nodes(args, connection)
    out: Path = args.out
    if len(drives) == 1 and not out.is_dir() and out.suffix:
        return backup_file(drives[0], out).as_dict()
    return _collect(run_per_drive(drives, lambda drive: backup_drive(drive, out / f"node{drive.node}")))


def _restore(args: argparse.Namespace, connection: BusConnection) -> object:
    drives = _nodes(args, connection)
    source: Path = args.source
    store = not args.no_store
    if len(drives) == 1 and source.is_file():
        result = restore_file(drives[0], source, store=store)
        if not result.ok:
            emit(result.as_dict())
            raise BackupError(restore_failure(result.as_dict()))
        return result.as_dict()
    return _collect(
        run_per_drive(drives, lambda drive: restore_drive(drive, source / f"node{drive.node}", store=store))
    )


def _store(args: argparse.Namespace, connection: BusConnection) -> object:
    return store_parameters(_drive(args, connection))


def _collect(results: dict[int, Sequence[FileResult] | Exception]) -> object:
    """Per-node results; the first failure decides the exit code after everything was tried."""
    shown = per_node(results)
    errors = [_failure(node, outcome) for node, outcome in results.items()]
    first = next((error for error in errors if error is not None), None)
    if first is not None:
        emit(shown)
        raise first
    return shown


def _failure(node: int, outcome: Sequence[FileResult] | Exception) -> Exception | None:
    """What failed on a node: its exception, or an incomplete restore."""
    if isinstance(outcome, Exception):
        return outcome
    if any(isinstance(item, RestoreResult) and not item.ok for item in outcome):
        return BackupError(f"node {node}: restore incomplete")
    return None


def restore_failure(result: dict) -> str:
    """Why a restore is incomplete, as the command reports it (here or through a server)."""
    problems = result.get("objects") or []
    detail = "; ".join(f"{item['label']}: {item['status']} {item['error']}".strip() for item in problems[:5])
    return f"restore of node {result['node']} incomplete: {result.get('error') or detail}"


def _io(args: argparse.Namespace, connection: BusConnection) -> object:
    drive, simulated = _drive(args, connection), connection.simulation is not None
    if not io_changes.asks_a_change(args):
        return io.read(drive, simulated)
    return io.apply(drive, io_changes.change_of(args), simulated)


def _nmt(args: argparse.Namespace, connection: BusConnection) -> object:
    command = connection.nmt(args.command_name, args.node)
    return {"command": command.name.lower().replace("_", "-"), "node": args.node}


def _fault(args: argparse.Namespace, connection: BusConnection) -> object:
    drive = _drive(args, connection)
    if args.reset:
        reset_faults(drive)
    return fault_report(drive).as_dict()


def _state(args: argparse.Namespace, connection: BusConnection) -> object:
    drive = _drive(args, connection)
    target = State.parse(args.target) if args.target else None
    if target is State.OPERATION_ENABLED:
        _hold_enabled(args.motion, (connection.id, drive.node), drive)
    elif target is not None:
        set_state(drive, target)
    state, statusword = read_state(drive)
    return {"node": drive.node, "state": state.value if state else None, "statusword": statusword}


def _hold_enabled(motion: MotionGuard, axis: Axis, drive: Drive) -> None:
    """Motion needs an armed, live controller: this command is it. It arms the axis, which stays enabled while the
    command runs; when it ends (Ctrl-C, SIGTERM, SIGHUP) the release quick-stops the axis."""
    stop = threading.Event()
    previous = {
        sig: signal.signal(sig, lambda *_: stop.set()) for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)
    }
    try:
        with motion.live_client(local_actor()) as actor:
            motion.arm(actor, axis)
            try:
                set_state(drive, State.OPERATION_ENABLED)
                print(
                    f"node {drive.node}: operation enabled; holding until Ctrl-C or SIGTERM, then quick stop",
                    file=sys.stderr,
                    flush=True,
                )
                stop.wait()
            finally:
                motion.release(actor, axis, drive)
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
