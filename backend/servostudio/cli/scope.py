"""``servostudio scope``: one oscilloscope capture of a drive's recorder into a CSV file (and an HTML file).

Pinned for scripts (issue #12)::

    servostudio scope --bus SPEC --node N --ch 0x606C,0 [--ch OBJ …] [--period-us 250] [--samples 2048]
        [--trigger OBJ:rising|falling|either:LEVEL | --immediate] [--pretrigger PCT] [--timeout S]
        --out FILE.csv [--html FILE.html]
    servostudio scope … --roll --seconds S --out FILE.csv

and, for drives without a recorder and several axes (docs/scope.md §7): ``--ch OBJ@NODE`` (a channel of another
axis of the bus), ``--source auto|recorder|tpdo|poll``, and ``--plan`` (print the plan — source, rate, bus load,
alignment — and arm nothing).

The files are the capture service's (docs/scope.md): written only once the recording is read completely, each
atomically, so a failed capture leaves none. Stdout gets a JSON summary (with ``arm`` and ``arm_note``: how a
recorder capture of several axes was armed, null otherwise); the exit code is the error's kind (3 refused
before anything was armed, 4 unknown node or object, 5 the bus or the drive failed or no recording in time).
With ``--server URL`` the server captures on its bus (``--bus`` names it, or its spec; default: its only bus) and
the files are written here the same way (``cli/scope_remote.py``).

``--roll`` streams the channels (up to 4 per axis, through TPDOs at the server's SYNC, 1 kHz at the fastest) for
``--seconds`` and writes every sample that arrived as the capture CSV, the gaps stated in ``# gap:`` comments
(``services/scope/rollfile.py``; over ``--server`` the roll's REST route and WebSocket). Ctrl-C ends the roll
early: the file holds what was rolled, and the exit code is 130.
"""

from __future__ import annotations

import argparse
import signal
import sys
import threading
from collections.abc import Callable
from pathlib import Path
from typing import TypeVar

from servostudio.api.routes.scope_models import plan_model
from servostudio.cli import remote, scope_remote
from servostudio.cli.output import emit
from servostudio.cli.server_drive import ServerBus
from servostudio.drive.access import Drive
from servostudio.drive.link import LinkDownError
from servostudio.formats.textfile import write_bytes_atomic
from servostudio.services.bus import BusConnection, ConnectionManager
from servostudio.services.cancel import Cancellation, Cancelled
from servostudio.services.scan import identified
from servostudio.services.scope import (
    Capture,
    CaptureDefinition,
    Trigger,
    capture,
    capture_csv,
    capture_html,
    check,
    identity_of,
    parse_trigger,
)
from servostudio.services.scope.definition import DEFAULT_PERIOD_US, DEFAULT_SAMPLES, SOURCES
from servostudio.services.scope.rollfile import RollRecord, roll_csv
from servostudio.services.scope.service import roll

T = TypeVar("T")
CONNECT_WAIT = 3.0
DEFAULT_TIMEOUT_S = 10.0
EXIT_INTERRUPTED = 130  # the shell's code for a command ended by Ctrl-C
ROLL_PERIOD_US = 1000.0  # the roll's default and fastest period: the SYNC producer's 1 ms


def register(commands: argparse._SubParsersAction) -> None:
    parser = commands.add_parser("scope", help="capture signals of one or several axes into a CSV file")
    parser.add_argument(
        "--bus",
        metavar="SPEC",
        help="e.g. socketcand:127.0.0.1:29536, sim; with --server the server's bus (default: its only bus)",
    )
    remote.add_options(parser, suppress=True)
    parser.add_argument("--node", type=int, required=True, help="node ID 1..127")
    parser.add_argument(
        "--ch",
        action="append",
        required=True,
        metavar="OBJ",
        help="channel: 0x606C,0, a name or statusword; OBJ@NODE for another axis of the bus",
    )
    parser.add_argument(
        "--period-us", type=float, help=f"sample period (default {DEFAULT_PERIOD_US:g} µs, {ROLL_PERIOD_US:g} to roll)"
    )
    parser.add_argument("--samples", type=int, default=DEFAULT_SAMPLES, help="samples per channel (default 2048)")
    trigger = parser.add_mutually_exclusive_group()
    trigger.add_argument("--trigger", metavar="OBJ:EDGE:LEVEL", help="e.g. 0x606C,0:rising:20480 (level in its unit)")
    trigger.add_argument("--immediate", action="store_true", help="record from the arm (the default)")
    parser.add_argument("--pretrigger", type=float, default=0.0, metavar="PCT", help="share before the trigger, %%")
    parser.add_argument("--timeout", type=float, default=DEFAULT_TIMEOUT_S, metavar="S", help="wait for the recording")
    parser.add_argument(
        "--source", choices=SOURCES, default="auto", help="recorder, TPDOs at the server's SYNC, or polling"
    )
    parser.add_argument("--plan", action="store_true", help="print the capture's plan (rate, bus load) and arm nothing")
    parser.add_argument("--roll", action="store_true", help="live roll mode: stream for --seconds into --out")
    parser.add_argument("--seconds", type=float, metavar="S", help="with --roll: how long to roll")
    parser.add_argument("--out", type=Path, metavar="FILE.csv")
    parser.add_argument("--html", type=Path, metavar="FILE.html", help="also a standalone interactive HTML file")
    parser.set_defaults(handler=lambda args: _scope(args, parser))


def definition_of(args: argparse.Namespace) -> CaptureDefinition:
    return CaptureDefinition(
        channels=tuple(args.ch),
        period_us=args.period_us or (ROLL_PERIOD_US if args.roll else DEFAULT_PERIOD_US),
        samples=args.samples,
        trigger=parse_trigger(args.trigger) if args.trigger else Trigger(),
        pre_trigger_pct=args.pretrigger,
        timeout_s=args.timeout,
        source="tpdo" if args.roll else args.source,
    )


def _scope(args: argparse.Namespace, parser: argparse.ArgumentParser) -> int:
    if args.out is None and not args.plan:
        parser.error("--out FILE.csv is needed (or --plan)")
    if args.roll:
        _check_roll(args, parser)
    definition = definition_of(args)  # refused before the bus (or the server) is asked
    server = remote.Remote.of(args)
    if server is not None:
        if args.roll:
            return _roll_through_server(args, ServerBus.of(server, args), definition)
        return _through_server(args, ServerBus.of(server, args), definition)
    if args.bus is None:
        parser.error("--bus SPEC is needed (or --server URL)")
    manager = ConnectionManager()
    try:
        connection = manager.open(args.bus, wait=CONNECT_WAIT)
        if not connection.link.connected:
            raise LinkDownError(f"bus {args.bus}: not connected ({connection.link.last_error or 'no answer'})")
        identified(connection, args.node)
        drive = connection.drive(args.node)
        bitrate = connection.spec.bitrate
        if args.roll:
            return _roll_here(args, connection, drive, definition)
        if args.plan:
            return emit(plan_model(check(drive, definition, connection.drive, bitrate)).model_dump())
        armed: dict[str, object] = {}  # how a recorder capture of several axes was armed (its "armed" event)
        made = _interruptible(lambda cancellation: capture(drive, identity_of(connection, drive), definition,
                                                           _armed_into(armed), cancellation, axes=connection.drive,
                                                           bitrate=bitrate))  # fmt: skip
    except Cancelled as stopped:
        print(f"error: {stopped}; the recorder was stopped", file=sys.stderr)
        return EXIT_INTERRUPTED
    finally:
        manager.close_all()
    return emit({**_write(made, args.out, args.html), "arm": armed.get("arm"), "arm_note": armed.get("note")})


def _armed_into(armed: dict[str, object]) -> Callable[[dict[str, object]], None]:
    """A progress callback keeping the ``armed`` event of a recorder capture of several axes (``arm``, ``note``)."""

    def keep(event: dict[str, object]) -> None:
        if event.get("stage") == "armed" and "arm" in event:
            armed.update(event)

    return keep


def _through_server(args: argparse.Namespace, bus: ServerBus, definition: CaptureDefinition) -> int:
    if args.plan:
        return emit(bus.call("POST", bus.path(args.node, "/scope/check"), definition.as_dict()))
    try:
        result = _interruptible(
            lambda cancellation: scope_remote.capture_through(bus, args.node, definition, cancellation)
        )
    except Cancelled as stopped:
        print(f"error: {stopped}; the recorder was stopped", file=sys.stderr)
        return EXIT_INTERRUPTED
    summary = scope_remote.write_files(bus, args.node, str(result["capture"]), args.out, args.html)
    return emit({**summary, "arm": result.get("arm"), "arm_note": result.get("arm_note")})


def _check_roll(args: argparse.Namespace, parser: argparse.ArgumentParser) -> None:
    """A roll streams from its start for a time: no trigger, depth, HTML or plan (its budget is checked anyway)."""
    given = [option for option, value in (("--trigger", args.trigger), ("--html", args.html), ("--plan", args.plan),
                                          ("--pretrigger", args.pretrigger)) if value]  # fmt: skip
    if given:
        parser.error(f"--roll does not take {', '.join(given)}")
    if args.seconds is None or args.seconds <= 0:
        parser.error("--roll needs --seconds S (S > 0)")


def _roll_here(args: argparse.Namespace, connection: BusConnection, drive: Drive, definition: CaptureDefinition) -> int:
    cancellation = Cancellation()  # kept: a roll ended by Ctrl-C is written, then exit 130
    record = _interruptible(lambda cancelled: roll(drive, identity_of(connection, drive), definition, args.seconds,
                                                   cancelled, connection.drive, connection.spec.bitrate),
                            cancellation)  # fmt: skip
    return _roll_written(record, args.out, cancellation)


def _roll_through_server(args: argparse.Namespace, bus: ServerBus, definition: CaptureDefinition) -> int:
    cancellation = Cancellation()
    record = _interruptible(
        lambda cancelled: scope_remote.roll_through(bus, args.node, definition, args.seconds, cancelled), cancellation
    )
    return _roll_written(record, args.out, cancellation)


def _roll_written(record: RollRecord, out: Path, cancellation: Cancellation) -> int:
    """The roll's CSV, atomically, and its summary; 130 when Ctrl-C ended it early."""
    write_bytes_atomic(out, roll_csv(record).encode("utf-8"))
    gaps = [{"from": start, "to": end, "reason": reason} for start, end, reason in record.gaps]
    emit({"out": str(out), "node": record.drive.node, "channels": [channel.key for channel in record.channels],
          "samples": len(record.rows), "period_us": record.period_ns / 1000, "gaps": gaps, "lost": record.lost,
          "source": "tpdo", "captured": record.started_at})  # fmt: skip
    return EXIT_INTERRUPTED if cancellation.requested else 0


def _interruptible(work: Callable[[Cancellation], T], cancellation: Cancellation | None = None) -> T:
    """Run ``work(cancellation)``; Ctrl-C or SIGTERM cancels it (the service then stops the recorder). Signals reach
    only the main thread: a command run from another thread (an embedding program) just runs."""
    cancellation = cancellation or Cancellation()
    signals = (signal.SIGINT, signal.SIGTERM) if threading.current_thread() is threading.main_thread() else ()
    handlers = {sig: signal.signal(sig, lambda *_: cancellation.cancel()) for sig in signals}
    try:
        return work(cancellation)
    finally:
        for sig, handler in handlers.items():
            signal.signal(sig, handler)


def _write(made: Capture, out: Path, html: Path | None) -> dict[str, object]:
    """The files, each atomically, and what the JSON summary says of them."""
    write_bytes_atomic(out, capture_csv(made).encode("utf-8"))
    if html is not None:
        write_bytes_atomic(html, capture_html(made).encode("utf-8"))
    return {
        "out": str(out),
        "html": str(html) if html is not None else None,
        "node": made.drive.node,
        "channels": [channel.key for channel in made.channels],
        "samples": made.samples,
        "period_us": made.period_ns / 1000,
        "trigger": made.trigger,
        "trigger_index": made.trigger_index,
        "captured": made.captured_at,
        "source": made.source,
        "alignment_ns": made.alignment_ns,
    }
