"""``servostudio seq …``: SEQUENCE.TXT checked, shown and graphed; sequence memory downloaded and uploaded; programs
run and stopped (docs/sequences.md).  Pinned by issue 15:

    seq check FILE | seq show FILE | seq graph FILE
    seq download --bus SPEC --node N FILE [--merge] [--store]
    seq upload --bus SPEC --node N --out FILE
    seq run --bus SPEC --node N SEQ [--watch SECONDS] [--input-bits PATTERN] [--sim-inputs PATTERN]
    seq stop --bus SPEC --node N

Each also through ``--server URL`` (``--bus`` then names the server's bus).  ``run`` prints one JSON line per
executed sequence, ``{"t", "sequence", "phase"}``: when it began (seconds after the start) and the last phase it
reached (END: it ran to its end).  It is the axis's live controller for as long as it runs, as ``state …
operation-enabled`` is: it arms the axis, starts the program, and when the program ends, ``--watch`` seconds have
passed or it is interrupted, it stops the program and releases the axis, which quick-stops it.
"""

from __future__ import annotations

import argparse
import json
import signal
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from servostudio.cli import remote
from servostudio.cli.audit import audit_log, guarded_connections, local_actor
from servostudio.cli.liveclient import LiveClient, axis_path
from servostudio.cli.output import emit
from servostudio.drive.access import Drive
from servostudio.drive.link import LinkDownError
from servostudio.formats.sequence import LoadMode, format_sequence_table
from servostudio.formats.textfile import FILE_ENCODING, write_text_atomic
from servostudio.services import sequences
from servostudio.services.audit import acting_as
from servostudio.services.bus import BusConnection
from servostudio.services.motion import MotionGuard
from servostudio.services.scan import identified

CONNECT_WAIT = 3.0
POLL = 0.02
STOP_WAIT = 5.0


def register(commands: argparse._SubParsersAction) -> None:
    seq = commands.add_parser("seq", help="sequence files, sequence memory and programs (XtrapulsPac sequence mode)")
    verbs = seq.add_subparsers(dest="seq_command", required=True)
    for name, text, handler in (
        ("check", "check a SEQUENCE.TXT (exit 3 with FILE:LINE reasons)", _check),
        ("show", "the sequences of a SEQUENCE.TXT as JSON", _show),
        ("graph", "the chaining graph of a SEQUENCE.TXT as JSON: nodes, edges with their kind, findings", _graph),
    ):
        parser = verbs.add_parser(name, help=text)
        parser.add_argument("file", type=Path, metavar="FILE")
        parser.set_defaults(handler=handler)
    download = _on_drive(verbs, "download", "validate, write, verify (and store) a SEQUENCE.TXT", _download)
    download.add_argument("file", type=Path, metavar="FILE")
    download.add_argument("--merge", action="store_true", help="MERGE: keep the sequences the file does not declare")
    download.add_argument("--store", action="store_true", help="store to flash (sseq) once verified")
    upload = _on_drive(verbs, "upload", "the sequence memory as SEQUENCE.TXT", _upload)
    upload.add_argument("--out", type=Path, required=True, metavar="FILE")
    run = _on_drive(verbs, "run", "run sequence SEQ, one JSON line per executed sequence", _run)
    run.add_argument("sequence", type=int, metavar="SEQ")
    run.add_argument("--watch", type=float, metavar="SECONDS", help="stop after this long (default: at its end)")
    run.add_argument("--input-bits", metavar="PATTERN", help='0x3601,3 before the start: a number or "1......."')
    run.add_argument("--sim-inputs", metavar="PATTERN", help="simulated drive only: IN5..IN1 (0x5F00), e.g. 10000")
    _on_drive(verbs, "stop", "stop the running program (control word bit 5), then release the axis", _stop)


def _on_drive(verbs: argparse._SubParsersAction, name: str, text: str, handler: Callable) -> argparse.ArgumentParser:
    parser = verbs.add_parser(name, help=text)
    parser.add_argument("--bus", required=True, metavar="SPEC", help="bus spec (with --server: the server's bus id)")
    parser.add_argument("--node", type=int, required=True, help="node ID 1..127")
    remote.add_options(parser, suppress=True)
    parser.set_defaults(handler=handler)
    return parser


# ---- files ------------------------------------------------------------------------------------------------------


def _read(path: Path) -> str:
    return path.read_text(encoding=FILE_ENCODING)


def _check(args: argparse.Namespace) -> int:
    table = sequences.parse(_read(args.file), str(args.file))
    return emit({"file": str(args.file), "ok": True, "sequences": list(table)})


def _show(args: argparse.Namespace) -> int:
    return emit(sequences.show(sequences.parse(_read(args.file), str(args.file))))


def _graph(args: argparse.Namespace) -> int:
    return emit(sequences.graph(sequences.parse(_read(args.file), str(args.file))))


# ---- the drive --------------------------------------------------------------------------------------------------


@contextmanager
def _opened(args: argparse.Namespace) -> Iterator[tuple[BusConnection, Drive, MotionGuard]]:
    """The bus, opened as the person at the terminal (motion guard, audit log), and the node's drive."""
    manager = guarded_connections(audit_log())
    try:
        with acting_as(local_actor()):
            connection = manager.open(args.bus, wait=CONNECT_WAIT)
            if not connection.link.connected:
                raise LinkDownError(f"bus {args.bus}: not connected ({connection.link.last_error or 'no answer'})")
            identified(connection, args.node)
            yield connection, connection.drive(args.node), manager.motion
    finally:
        manager.close_all()


def _download(args: argparse.Namespace) -> int:
    text, mode = _read(args.file), LoadMode.MERGE if args.merge else LoadMode.LOAD
    server = remote.Remote.of(args)
    if server is not None:
        body = {"text": text, "file": args.file.name, "mode": mode.value, "store": args.store}
        return emit(server.call("PUT", f"{axis_path(args.bus, args.node)}/sequences", body))
    with _opened(args) as (_, drive, _):
        return emit(sequences.download(drive, text, mode, args.store, args.file.name).as_dict())


def _upload(args: argparse.Namespace) -> int:
    server = remote.Remote.of(args)
    if server is not None:
        text = server.call("GET", f"{axis_path(args.bus, args.node)}/sequences")["text"]
    else:
        with _opened(args) as (_, drive, _):
            text = format_sequence_table(sequences.upload(drive))
    write_text_atomic(args.out, text)
    return emit({"node": args.node, "file": str(args.out), "sequences": list(sequences.parse(text))})


# ---- running ----------------------------------------------------------------------------------------------------


class _Printer:
    """One JSON line per executed sequence, once it is over (the next one began or the program ended)."""

    def __init__(self, since: float) -> None:
        self.since, self.printed = since, 0

    def runs(self, executed: list[dict[str, Any]], running: bool) -> None:
        done = executed if not running else executed[:-1]
        for run in done[self.printed :]:
            line = {"t": round(float(run["t"]) - self.since, 4), "sequence": run["sequence"], "phase": run["phase"]}
            print(json.dumps(line), flush=True)
        self.printed = max(self.printed, len(done))


def _run(args: argparse.Namespace) -> int:
    sequences.parse_bits(args.input_bits or "0", 16)  # a bad pattern is refused before the bus is asked
    sequences.parse_bits(args.sim_inputs or "0", 5)
    server = remote.Remote.of(args)
    with _stop_signal() as stop:
        return _run_remote(args, server, stop) if server is not None else _run_here(args, stop)


def _run_here(args: argparse.Namespace, stop: threading.Event) -> int:
    with _opened(args) as (connection, drive, motion), motion.live_client(local_actor()) as actor:
        axis = (connection.id, drive.node)
        monitor = sequences.SequenceMonitor(connection, drive, sequences.upload(drive)).start()
        motion.arm(actor, axis)
        try:
            _set_inputs(args, drive)
            since = float(monitor.snapshot()["now"])  # type: ignore[arg-type]
            sequences.start(motion, connection.id, drive, args.sequence)
            _follow(lambda: monitor.snapshot(), _Printer(since), args.watch, stop)
            sequences.stop(drive)
            _wait_idle(lambda: monitor.running)
        finally:
            monitor.stop()
            motion.release(actor, axis, drive)
    return 0


def _set_inputs(args: argparse.Namespace, drive: Drive) -> None:
    if args.sim_inputs is not None:
        sequences.set_sim_inputs(drive, args.sim_inputs)
    if args.input_bits is not None:
        sequences.set_conditional_input(drive, args.input_bits)


def _follow(
    snapshot: Callable[[], dict[str, Any]], printer: _Printer, watch: float | None, stop: threading.Event
) -> None:
    """Print the executed sequences until the program ended, ``watch`` seconds passed or a signal came."""
    deadline = time.monotonic() + watch if watch is not None else None
    began = False
    while True:
        state = snapshot()
        began = began or bool(state["executed"][printer.printed :])
        printer.runs(state["executed"], bool(state["running"]))
        if (began and not state["running"]) or stop.is_set() or (deadline and time.monotonic() > deadline):
            printer.runs(state["executed"], False)
            return
        time.sleep(POLL)


def _wait_idle(running: Callable[[], bool]) -> None:
    deadline = time.monotonic() + STOP_WAIT
    while running() and time.monotonic() < deadline:
        time.sleep(POLL)


@contextmanager
def _stop_signal() -> Iterator[threading.Event]:
    """Set by Ctrl-C, SIGTERM or SIGHUP while the block runs (signals reach the main thread only)."""
    stop = threading.Event()
    signals = (
        (signal.SIGINT, signal.SIGTERM, signal.SIGHUP) if threading.current_thread() is threading.main_thread() else ()
    )
    previous = {sig: signal.signal(sig, lambda *_: stop.set()) for sig in signals}
    try:
        yield stop
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)


def _run_remote(args: argparse.Namespace, server: remote.Remote, stop: threading.Event) -> int:
    path = f"{axis_path(args.bus, args.node)}/sequences"
    with LiveClient(server) as client, client.holding(args.bus, args.node):
        client.call("POST", f"{path}/monitor?fresh=true")
        if args.input_bits is not None or args.sim_inputs is not None:
            client.call("PUT", f"{path}/inputs", {"conditional": args.input_bits, "sim": args.sim_inputs})
        since = float(client.call("GET", f"{path}/monitor")["now"])
        client.call("POST", f"{path}/start", {"sequence": args.sequence})
        try:
            _follow(lambda: client.call("GET", f"{path}/monitor"), _Printer(since), args.watch, stop)
        finally:
            client.call("POST", f"{path}/stop")
    return 0


def _stop(args: argparse.Namespace) -> int:
    server = remote.Remote.of(args)
    if server is not None:
        with LiveClient(server) as client, client.holding(args.bus, args.node):
            return emit(client.call("POST", f"{axis_path(args.bus, args.node)}/sequences/stop"))
    with _opened(args) as (connection, drive, motion), motion.live_client(local_actor()) as actor:
        axis = (connection.id, drive.node)
        motion.arm(actor, axis)
        try:
            result = sequences.stop(drive)
            _wait_idle(lambda: int(drive.read("sequence_executed").raw) >= 0)
        finally:
            motion.release(actor, axis, drive)
    return emit(result)
