"""The frequency response from the command line (issue #16 item 6, pinned):

    servostudio bode --bus SPEC --node N --loop plant|closed [--from 5] [--to 400] [--points 60] [--amplitude PCT]
                     [--yes] --out FILE.csv
    (also with --server URL [--token TOKEN]: --bus then names the server's bus, by id or spec)

The CSV has the pinned columns ``freq_hz,magnitude_db,phase_deg,coherence`` after ``# key: value`` comment lines
(services/frequency/store.py); plant magnitude in dB of (rad/s)/(N·m), closed loop in dB of actual / demanded
speed.  Stdout gets the result without its points (markers, plant fit, excitation) and the file written.  The motor
turns: without ``--yes`` the command asks first (no terminal: exit 3, nothing written).  Exit codes: 3 refused
(options, no recorder, no confirmation), 4 unknown node, 5 a limit was exceeded (the axis was quick-stopped; the
CSV has no points and the reason on its ``# aborted:`` line) or the bus failed, 130 after Ctrl-C (the axis is
stopped, nothing written).  Extra options, not pinned: ``--base-speed`` rad/s, ``--window`` revolutions,
``--current-limit`` A, ``--periods``.
"""

from __future__ import annotations

import argparse
import sys
import threading
from dataclasses import asdict
from pathlib import Path
from typing import Any

from servostudio.cli import remote
from servostudio.cli.audit import audit_log, guarded_connections, local_actor
from servostudio.cli.jobrun import follow_job, forward_interrupt, interruptible
from servostudio.cli.liveclient import LiveClient, axis_path
from servostudio.cli.output import emit
from servostudio.cli.procedures import EXIT_INTERRUPTED, confirm
from servostudio.drive.link import LinkDownError
from servostudio.errors import CommunicationError
from servostudio.formats.textfile import write_bytes_atomic
from servostudio.services.audit import acting_as
from servostudio.services.cancel import Cancellation, Cancelled
from servostudio.services.frequency.measure import MeasureRequest
from servostudio.services.frequency.service import FrequencyRequest, FrequencyService
from servostudio.services.frequency.store import points_csv
from servostudio.services.scan import identified

CONNECT_WAIT = 3.0
EXIT_ABORTED = 5


class MeasurementFailed(CommunicationError):
    """The server's measurement job failed (its reason: the drive, the link, a refusal)."""


class MeasurementAborted(CommunicationError):
    """A limit was exceeded: the axis was quick-stopped and the measurement has no points."""


def register(commands: argparse._SubParsersAction) -> None:
    parser = commands.add_parser(
        "bode", help="frequency response of the plant or the closed speed loop (turns the motor)"
    )
    parser.add_argument("--bus", required=True, metavar="SPEC", help="bus spec (with --server: the server's bus)")
    parser.add_argument("--node", type=int, required=True, help="node ID 1..127")
    parser.add_argument("--loop", required=True, choices=("plant", "closed"))
    parser.add_argument("--from", dest="from_hz", type=float, default=5.0, metavar="HZ")
    parser.add_argument("--to", dest="to_hz", type=float, default=400.0, metavar="HZ")
    parser.add_argument("--points", type=int, default=60)
    parser.add_argument(
        "--amplitude",
        type=float,
        metavar="PCT",
        help="plant: %% of the rated current (50); closed: %% of the base speed (40)",
    )
    parser.add_argument("--base-speed", type=float, default=10.0, metavar="RAD_S")
    parser.add_argument("--window", type=float, default=10.0, metavar="REV", help="travel allowed, revolutions")
    parser.add_argument("--current-limit", type=float, metavar="A")
    parser.add_argument("--periods", type=int, default=4)
    parser.add_argument("--yes", action="store_true", help="do not ask before the motor turns")
    parser.add_argument("--out", required=True, type=Path, metavar="FILE.csv")
    remote.add_options(parser, suppress=True)
    parser.set_defaults(handler=_run)


def request_of(args: argparse.Namespace) -> MeasureRequest:
    return MeasureRequest(
        loop=args.loop,
        from_hz=args.from_hz,
        to_hz=args.to_hz,
        points=args.points,
        amplitude_pct=args.amplitude,
        base_speed_rad_s=args.base_speed,
        position_window=args.window,
        current_limit_a=args.current_limit,
        periods=args.periods,
    )


def _run(args: argparse.Namespace) -> int:
    server = remote.Remote.of(args)
    request = request_of(args)
    with interruptible() as interrupted:
        result = _remote(args, server, request, interrupted) if server else _local(args, request, interrupted)
    if result is None:
        print("error: frequency response interrupted; the axis is stopped, nothing written", file=sys.stderr)
        return EXIT_INTERRUPTED
    write_bytes_atomic(args.out, points_csv(result).encode("utf-8"))
    emit(
        {key: value for key, value in result.items() if key != "points"}
        | {"out": str(args.out), "points": len(result.get("points", []))}
    )
    if result.get("aborted"):
        raise MeasurementAborted(f"frequency response aborted: {result['aborted']} (the axis was stopped)")
    return 0


def _question(args: argparse.Namespace) -> str:
    return (
        f"frequency response ({args.loop}) on node {args.node} of bus {args.bus}: the motor will turn at "
        f"{args.base_speed:g} rad/s for several seconds, up to {args.window:g} revolutions"
    )


def _local(args: argparse.Namespace, request: MeasureRequest, interrupted: threading.Event) -> dict[str, Any] | None:
    manager = guarded_connections(audit_log())
    try:
        with acting_as(local_actor()):
            connection = manager.open(args.bus, wait=CONNECT_WAIT)
            if not connection.link.connected:
                raise LinkDownError(f"bus {args.bus}: not connected ({connection.link.last_error or 'no answer'})")
            identified(connection, args.node)
            drive = connection.drive(args.node)
            guard, axis, service = manager.motion, (connection.id, args.node), FrequencyService()
            with guard.live_client(local_actor()) as actor:
                guard.arm(actor, axis)
                try:
                    service.check(guard, axis, drive, FrequencyRequest(request), connection.spec.bitrate)
                    confirm(args, _question(args))
                    cancellation = Cancellation()
                    stop_watching = forward_interrupt(interrupted, cancellation)
                    try:
                        return service.run(guard, connection, drive, FrequencyRequest(request), _progress, cancellation)
                    except Cancelled:
                        return None
                    finally:
                        stop_watching()
                finally:
                    guard.release(actor, axis, drive)
    finally:
        manager.close_all()


def _remote(
    args: argparse.Namespace, server: remote.Remote, request: MeasureRequest, interrupted: threading.Event
) -> dict[str, Any] | None:
    bus = server.bus(args.bus)
    body = {key: value for key, value in asdict(request).items() if value is not None}
    with LiveClient(server) as live, live.holding(bus, args.node):
        confirm(args, _question(args))
        job = live.call("POST", f"{axis_path(bus, args.node)}/frequency-response", body)
        ended = follow_job(live, job["id"], interrupted)
    if ended["state"] == "failed":
        raise MeasurementFailed(str(ended["error"]))
    return None if interrupted.is_set() else dict(ended["result"])


def _progress(event: dict[str, object]) -> None:
    fraction = event.get("fraction")
    shown = f" {float(fraction) * 100:.0f} %" if isinstance(fraction, (int, float)) else ""
    print(f"{event.get('stage')}{shown}", file=sys.stderr, flush=True)
