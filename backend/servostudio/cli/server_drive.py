"""The drive commands through a running server (``--server URL``, or the default of ``cli.remote``): the same
commands, output and exit codes as on a bus of their own, so scripts, the browser and the terminal share one bus
(docs/drive-access.md, "The CLI through a server").

Each command is one or a few REST calls on the server's bus (``--bus`` names it or its spec; without it the server's
only bus).  Files stay on this machine: a backup downloads the drive's file and writes it here atomically, a restore
uploads the local file; the server validates, writes, verifies and stores it as for the browser.
"""

from __future__ import annotations

import argparse
import json
import signal
import sys
import threading
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from servostudio.cli import io_changes
from servostudio.cli.output import emit
from servostudio.cli.remote import Remote, quoted
from servostudio.drive.cia402 import State
from servostudio.drive.nmt import NmtCommand
from servostudio.drive.profiles import profile_for
from servostudio.errors import ServoStudioError
from servostudio.formats.textfile import FILE_ENCODING, write_text_atomic
from servostudio.services.backup import BackupError, FileKind, RestoreValidationError, no_files, profile_file_kinds
from servostudio.services.scan import NothingFound

SCAN_HINT_HEADER = "x-scan-hint"
BACKUP_RESULT_HEADER = "x-backup-result"
Outcome = list[dict[str, Any]] | ServoStudioError


@dataclass(frozen=True)
class ServerBus:
    """One bus of a running server, as the drive commands use it."""

    remote: Remote
    bus: str

    @classmethod
    def of(cls, remote: Remote, args: argparse.Namespace) -> ServerBus:
        return cls(remote, remote.bus(getattr(args, "bus", None)))

    def path(self, node: int | None = None, tail: str = "") -> str:
        base = f"/api/buses/{quoted(self.bus)}"
        return (base if node is None else f"{base}/nodes/{node}") + tail

    def call(self, method: str, path: str, body: dict[str, Any] | None = None) -> Any:
        return self.remote.call(method, path, body)


def _device(args: argparse.Namespace) -> str:
    device = getattr(args, "device", None)
    return f"?device={quoted(device)}" if device else ""


def _joined(query: str, extra: str) -> str:
    return f"{query}&{extra}" if query else f"?{extra}"


# ------------------------------------------------------------------------------------------------- commands --
def scan(args: argparse.Namespace, bus: ServerBus) -> object:
    """The nodes found; none is a failure (exit 4) with the server's reasons, after the empty list."""
    found, hint = _scanned(bus)
    if not found:
        emit(found)
        raise NothingFound(hint)
    return found


def _scanned(bus: ServerBus) -> tuple[list[dict[str, Any]], str]:
    """The server's scan of its bus, and why it may look empty (the server's ``X-Scan-Hint``)."""
    content, headers = bus.remote.exchange("POST", bus.path(tail="/scan"))
    return json.loads(content), headers.get(SCAN_HINT_HEADER) or f"no node answered on bus {bus.bus}"


def read(args: argparse.Namespace, bus: ServerBus) -> object:
    values = [bus.call("GET", bus.path(args.node, f"/objects/{quoted(key)}{_device(args)}")) for key in args.objects]
    return values[0] if len(values) == 1 else values


def write(args: argparse.Namespace, bus: ServerBus) -> object:
    body = {"value": args.value, "physical": args.physical}
    return bus.call("PUT", bus.path(args.node, f"/objects/{quoted(args.object)}{_device(args)}"), body)


def nmt(args: argparse.Namespace, bus: ServerBus) -> object:
    command = NmtCommand.parse(args.command_name)  # refused here, before the server is asked
    name = command.name.lower().replace("_", "-")
    bus.call("POST", bus.path(tail="/nmt"), {"command": name, "node": args.node})
    return {"command": name, "node": args.node}


def fault(args: argparse.Namespace, bus: ServerBus) -> object:
    if args.reset:
        return bus.call("POST", bus.path(args.node, f"/faults/reset{_device(args)}"))
    return bus.call("GET", bus.path(args.node, f"/faults{_device(args)}"))


def io(args: argparse.Namespace, bus: ServerBus) -> object:
    if not io_changes.asks_a_change(args):
        return bus.call("GET", bus.path(args.node, f"/io{_device(args)}"))
    return bus.call("PUT", bus.path(args.node, f"/io{_device(args)}"), io_changes.change_body(args))


def state(args: argparse.Namespace, bus: ServerBus) -> object:
    target = State.parse(args.target) if args.target else None
    if target is State.OPERATION_ENABLED:
        _hold_enabled(args, bus)
    elif target is not None:
        bus.call("PUT", bus.path(args.node, f"/state{_device(args)}"), {"target": args.target})
    answer = bus.call("GET", bus.path(args.node, f"/state{_device(args)}"))
    return {"node": answer["node"], "state": answer["state"], "statusword": answer["statusword"]}


def _hold_enabled(args: argparse.Namespace, bus: ServerBus) -> None:
    """This command is the axis's live client (an event socket of its own, ``cli.liveclient``): it arms the axis,
    enables it and holds it until interrupted; closing the socket makes the server quick-stop it."""
    from servostudio.cli.liveclient import LiveClient

    stop = threading.Event()
    previous = {
        sig: signal.signal(sig, lambda *_: stop.set()) for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)
    }
    try:
        with LiveClient(bus.remote) as live, live.holding(bus.bus, args.node):
            live.call("PUT", bus.path(args.node, f"/state{_device(args)}"), {"target": args.target})
            print(
                f"node {args.node}: operation enabled through {bus.remote.url}; holding until Ctrl-C or SIGTERM, "
                "then quick stop",
                file=sys.stderr,
                flush=True,
            )
            stop.wait()
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)


def share(args: argparse.Namespace, bus: ServerBus) -> object:
    """Share the server's bus as a socketcand endpoint (or stop sharing it): its address, for ``canopen``."""
    if args.off:
        bus.call("DELETE", bus.path(tail="/share"))
        return {"bus": bus.bus, "shared": False}
    return bus.call("PUT", bus.path(tail="/share"), {"host": args.host, "port": args.port})


# ------------------------------------------------------------------------------------------ backup / restore --
def backup(args: argparse.Namespace, bus: ServerBus) -> object:
    out: Path = args.out
    nodes = _nodes(args, bus)
    if len(nodes) == 1 and not out.is_dir() and out.suffix:
        return _download(args, bus, nodes[0][0], FileKind.from_path(out), out)

    def one(node: int, device: str | None) -> list[dict[str, Any]]:
        kinds = profile_file_kinds(profile_for(device))
        folder = out / f"node{node}"
        folder.mkdir(parents=True, exist_ok=True)
        return [_download(args, bus, node, kind, folder / kind.value) for kind in kinds]

    return _collected(_per_node(nodes, one))


def restore(args: argparse.Namespace, bus: ServerBus) -> object:
    source: Path = args.source
    store = "false" if args.no_store else "true"
    nodes = _nodes(args, bus)
    if len(nodes) == 1 and source.is_file():
        result = _upload(args, bus, nodes[0][0], FileKind.from_path(source), source, store)
        if not result["ok"]:
            from servostudio.cli.drive import restore_failure  # the command module builds on this one

            emit(result)
            raise BackupError(restore_failure(result))
        return result

    def one(node: int, device: str | None) -> list[dict[str, Any]]:
        folder = source / f"node{node}"
        possible = profile_file_kinds(profile_for(device))
        kinds = [kind for kind in possible if (folder / kind.value).is_file()]
        if not kinds:
            raise no_files(node, possible)
        return [_upload(args, bus, node, kind, folder / kind.value, store) for kind in kinds]

    return _collected(_per_node(nodes, one))


def store(args: argparse.Namespace, bus: ServerBus) -> object:
    return bus.call("POST", bus.path(args.node, f"/store{_device(args)}"))


def _download(args: argparse.Namespace, bus: ServerBus, node: int, kind: FileKind, path: Path) -> dict[str, Any]:
    content, headers = bus.remote.exchange("GET", bus.path(node, f"/files/{kind.value}{_device(args)}"))
    write_text_atomic(path, content.decode(FILE_ENCODING))
    result: dict[str, Any] = json.loads(headers.get(BACKUP_RESULT_HEADER) or "{}")
    return {**result, "node": node, "file": str(path), "kind": kind.value}


def _upload(
    args: argparse.Namespace, bus: ServerBus, node: int, kind: FileKind, path: Path, store: str
) -> dict[str, Any]:
    try:
        data = path.read_bytes()
    except OSError as error:
        raise RestoreValidationError(f"{path.name}: {error.strerror} — nothing was written to node {node}") from None
    query = _joined(_device(args), f"store={store}")
    content, _ = bus.remote.exchange("PUT", bus.path(node, f"/files/{kind.value}{query}"), data, "text/plain")
    return {**json.loads(content), "file": str(path)}


def _nodes(args: argparse.Namespace, bus: ServerBus) -> list[tuple[int, str | None]]:
    """The nodes given (their device as the server knows it, or ``--device``), or every identified node a scan of
    the server's bus finds."""
    if args.node:
        if not args.device:  # the server identifies a node on first use; one that does not answer fails here
            for node in args.node:  # by its semantic name: a PROFIBUS-DP drive has no 0x1000, every drive a status word
                bus.call("GET", bus.path(node, "/objects/statusword"))
        known = {item["node"]: item.get("device") for item in bus.call("GET", bus.path())["nodes"]}
        return [(node, args.device or known.get(node)) for node in args.node]
    found, hint = _scanned(bus)
    if not found:
        raise NothingFound(hint)
    return [(item["node"], item["device"]) for item in found if item.get("device")]


def _per_node(
    nodes: list[tuple[int, str | None]], work: Callable[[int, str | None], list[dict[str, Any]]]
) -> dict[int, Outcome]:
    """``work`` for every node in parallel (the server runs each drive's transfers back to back)."""

    def guarded(node: int, device: str | None) -> Outcome:
        try:
            return work(node, device)
        except ServoStudioError as error:
            return error

    with ThreadPoolExecutor(max_workers=max(1, len(nodes))) as pool:
        futures = {node: pool.submit(guarded, node, device) for node, device in nodes}
        return {node: future.result() for node, future in futures.items()}


def _collected(results: dict[int, Outcome]) -> object:
    """Per node, as ``cli.drive`` shows it: the file results, or ``{"error"}``; the first failure sets the exit."""
    shown = {
        str(node): ({"error": str(item)} if isinstance(item, Exception) else item) for node, item in results.items()
    }
    failures = [_failure(node, item) for node, item in results.items()]
    first = next((failure for failure in failures if failure is not None), None)
    if first is not None:
        emit(shown)
        raise first
    return shown


def _failure(node: int, outcome: Outcome) -> Exception | None:
    if isinstance(outcome, Exception):
        return outcome
    if any(item.get("ok") is False for item in outcome):
        return BackupError(f"node {node}: restore incomplete")
    return None
