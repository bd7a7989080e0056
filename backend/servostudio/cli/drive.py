"""Drive commands: ``servostudio scan|read|write|backup|restore|nmt|fault|state --bus SPEC [--node N] …``.

Each command opens the bus, does its work, prints JSON on stdout and exits with a code that says what went wrong
(see ``servostudio.cli.output``): 3 invalid input (nothing written), 4 unknown node/object, 5 communication.
"""

from __future__ import annotations

import argparse
import signal
import sys
import threading
from collections.abc import Callable
from pathlib import Path

from servostudio.cli.output import (
    EXIT_COMMUNICATION,
    EXIT_INVALID_INPUT,
    EXIT_NOT_FOUND,
    CommandError,
    emit,
)
from servostudio.drive.access import Drive, DriveAccessError, UnknownObjectError
from servostudio.drive.cia402 import State
from servostudio.drive.control import StateChangeError, fault_report, read_state, reset_faults, set_state
from servostudio.drive.link import LinkDownError
from servostudio.drive.nmt import NmtCommand, send_nmt
from servostudio.drive.profiles import ProfileError
from servostudio.drive.sdo import SdoError
from servostudio.services.backup import (
    BackupError,
    RestoreValidationError,
    backup_drive,
    backup_file,
    drive_file_kinds,
    restore_file,
    run_per_drive,
)
from servostudio.services.bus import BusConnection, ConnectionManager, UnknownBusOrNode
from servostudio.services.scan import identify, scan
from servostudio.transport.spec import BusSpecError

CONNECT_WAIT = 3.0


def register(commands: argparse._SubParsersAction) -> None:
    def add(
        name: str, help_text: str, handler: Callable[[argparse.Namespace, BusConnection], object], node: str = "one"
    ) -> argparse.ArgumentParser:
        parser = commands.add_parser(name, help=help_text)
        parser.add_argument(
            "--bus",
            required=True,
            metavar="SPEC",
            help="e.g. socketcand:127.0.0.1:29536, serial:/dev/ttyUSB0@19200, socketcan:can0, sim",
        )
        if node == "one":
            parser.add_argument("--node", type=int, required=True, help="node ID 1..127")
            parser.add_argument("--device", help="device key when the node does not identify itself")
        elif node == "many":
            parser.add_argument("--node", type=int, action="append", help="node ID, repeatable (default: scan)")
            parser.add_argument("--device", help="device key of the given nodes when they do not identify themselves")
        parser.set_defaults(handler=lambda args: _run(args, handler))
        return parser

    add("scan", "find and identify the nodes of a bus", _scan, node="none")
    read = add("read", "read objects of a node", _read)
    read.add_argument("objects", nargs="+", metavar="OBJECT", help="0x6041, 0x60F9,2, a name, or statusword")
    write = add("write", "write an object of a node (checked before anything is sent)", _write)
    write.add_argument("object", metavar="OBJECT")
    write.add_argument("value", metavar="VALUE", help="number, 0x hex, enumeration label or text")
    write.add_argument("--physical", action="store_true", help="VALUE is in the object's unit")
    backup = add("backup", "back up drive files (DRIVEPAR.TXT, USER_PAR.TXT, SEQUENCE.TXT)", _backup, node="many")
    backup.add_argument(
        "--out",
        type=Path,
        required=True,
        help="file (one node: kind from its name) or directory (DIR/node<N>/ per node)",
    )
    restore = add("restore", "validate, write, verify and store drive files", _restore, node="many")
    restore.add_argument("--in", dest="source", type=Path, required=True, help="file (one node) or directory")
    restore.add_argument("--no-store", action="store_true", help="do not store to flash afterwards")
    nmt = add("nmt", "send an NMT command", _nmt, node="none")
    nmt.add_argument(
        "command_name", metavar="COMMAND", help="start, stop, pre-operational, reset-node, reset-communication"
    )
    nmt.add_argument("--node", type=int, default=0, help="node ID (default 0: all nodes)")
    fault = add("fault", "show active faults with the manual's remedy; --reset resets them", _fault)
    fault.add_argument("--reset", action="store_true")
    state = add(
        "state",
        "show the CiA 402 state, or walk to TARGET (operation-enabled holds the axis enabled "
        "until the command is interrupted, then quick-stops it)",
        _state,
    )
    state.add_argument(
        "target",
        nargs="?",
        help="switch-on-disabled, ready-to-switch-on, switched-on, operation-enabled, quick-stop-active",
    )


def _run(args: argparse.Namespace, handler: Callable[[argparse.Namespace, BusConnection], object]) -> int:
    manager = ConnectionManager()
    try:
        connection = manager.open(args.bus, wait=CONNECT_WAIT)
        if not connection.link.connected:
            raise CommandError(
                f"bus {args.bus}: not connected ({connection.link.last_error or 'no answer'})", EXIT_COMMUNICATION
            )
        return emit(handler(args, connection))
    except (UnknownBusOrNode, ProfileError, UnknownObjectError) as error:
        raise CommandError(str(error), EXIT_NOT_FOUND) from None
    except (RestoreValidationError, DriveAccessError, BusSpecError, ValueError) as error:
        raise CommandError(str(error), EXIT_INVALID_INPUT) from None
    except (SdoError, BackupError, LinkDownError, StateChangeError) as error:
        raise CommandError(str(error), EXIT_COMMUNICATION) from None
    finally:
        manager.close_all()


def _drive(args: argparse.Namespace, connection: BusConnection, node: int | None = None) -> Drive:
    node = node if node is not None else args.node
    device = getattr(args, "device", None)
    if device is None:
        info = identify(connection, node)
        if info is None:
            raise CommandError(f"node {node} does not answer on {connection.spec}", EXIT_COMMUNICATION)
        if info.device is None:
            raise CommandError(
                f"node {node} (vendor 0x{info.vendor_id or 0:X}, product 0x{info.product_code or 0:X}) "
                "matches no dictionary of the EDS library; give --device",
                EXIT_NOT_FOUND,
            )
    return connection.drive(node, device)


def _nodes(args: argparse.Namespace, connection: BusConnection) -> list[Drive]:
    if args.node:
        return [_drive(args, connection, node) for node in args.node]
    found = scan(connection)
    if not found:
        raise CommandError(f"no node answers on {connection.spec}", EXIT_COMMUNICATION)
    return [connection.drive(info.node) for info in found if info.device]


def _scan(args: argparse.Namespace, connection: BusConnection) -> object:
    return [info.as_dict() for info in scan(connection)]


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
    results = run_per_drive(drives, lambda drive: backup_drive(drive, out / f"node{drive.node}"))
    return _collect(results, lambda items: [item.as_dict() for item in items])


def _restore(args: argparse.Namespace, connection: BusConnection) -> object:
    drives = _nodes(args, connection)
    source: Path = args.source
    if len(drives) == 1 and source.is_file():
        result = restore_file(drives[0], source, store=not args.no_store)
        if not result.ok:
            emit(result.as_dict())
            raise BackupError(_restore_failure(result.as_dict()))
        return result.as_dict()

    def restore_all(drive: Drive) -> list:
        folder = source / f"node{drive.node}"
        kinds = [kind for kind in drive_file_kinds(drive) if (folder / kind.value).is_file()]
        if not kinds:
            raise RestoreValidationError(
                f"{folder}: no DRIVEPAR.TXT, USER_PAR.TXT or SEQUENCE.TXT for node {drive.node}"
            )
        return [restore_file(drive, folder / kind.value, kind, store=not args.no_store) for kind in kinds]

    results = run_per_drive(drives, restore_all)
    return _collect(
        results,
        lambda items: [item.as_dict() for item in items],
        failed=lambda items: any(not item.ok for item in items),
    )


def _collect(
    results: dict[int, object], show: Callable[[object], object], failed: Callable[[object], bool] = lambda _: False
) -> object:
    """Per-node results; the first failure decides the exit code after everything was tried."""
    shown: dict[str, object] = {}
    errors = []
    for node, outcome in results.items():
        if isinstance(outcome, Exception):
            shown[str(node)] = {"error": str(outcome)}
            errors.append(outcome)
        else:
            shown[str(node)] = show(outcome)
            if failed(outcome):
                errors.append(BackupError(f"node {node}: restore incomplete"))
    if errors:
        emit(shown)
        raise errors[0]
    return shown


def _restore_failure(result: dict) -> str:
    problems = result.get("objects") or []
    detail = "; ".join(f"{item['label']}: {item['status']} {item['error']}".strip() for item in problems[:5])
    return f"restore of node {result['node']} incomplete: {result.get('error') or detail}"


def _nmt(args: argparse.Namespace, connection: BusConnection) -> object:
    command = NmtCommand.parse(args.command_name)
    send_nmt(connection.link, command, args.node)
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
        _hold_enabled(drive)
    elif target is not None:
        set_state(drive, target)
    state, statusword = read_state(drive)
    return {"node": drive.node, "state": state.value if state else None, "statusword": statusword}


def _hold_enabled(drive: Drive) -> None:
    """Motion needs a live client: this command is it. The axis stays enabled while the command runs and gets a
    quick stop when it ends (Ctrl-C, SIGTERM, SIGHUP)."""
    stop = threading.Event()
    previous = {
        sig: signal.signal(sig, lambda *_: stop.set()) for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)
    }
    try:
        set_state(drive, State.OPERATION_ENABLED)
        print(
            f"node {drive.node}: operation enabled; holding until Ctrl-C or SIGTERM, then quick stop",
            file=sys.stderr,
            flush=True,
        )
        stop.wait()
    finally:
        set_state(drive, State.QUICK_STOP_ACTIVE)
        for sig, handler in previous.items():
            signal.signal(sig, handler)
