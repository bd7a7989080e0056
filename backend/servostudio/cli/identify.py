"""Tool-side identification from the command line (issue #16 item 6, pinned; JSON on stdout):

    servostudio identify --bus SPEC --node N [--speed RPM] [--acceleration RPM_S] [--hold S] [--window REV]
                         [--current-limit PCT] [--cycles N] [--bandwidth HZ] [--yes]
    (also with --server URL [--token TOKEN]: --bus then names the server's bus, by id or spec)

The answer is the identification service's result, the same JSON its job ends with (docs/identification.md); its
``identified`` has the keys of ``autotune``'s: inertia_kgm2, viscous_friction_nms_per_rad, coulomb_friction_nm,
load_torque_nm, residual, inertia_ratio. Confirmation, the live controller, interruption (the axis is quick-stopped,
disabled and its objects put back; exit 130) and the exit codes are those of the procedure commands (cli/procedures.py).
"""

from __future__ import annotations

import argparse
import sys
import threading
from typing import Any

from servostudio.cli import remote
from servostudio.cli.audit import audit_log, guarded_connections, local_actor
from servostudio.cli.jobrun import follow_job, forward_interrupt, interruptible
from servostudio.cli.jobrun import print_progress as progress
from servostudio.cli.liveclient import LiveClient, axis_path
from servostudio.cli.output import emit
from servostudio.cli.procedures import CONNECT_WAIT, EXIT_INTERRUPTED, confirm
from servostudio.drive.link import LinkDownError
from servostudio.errors import CommunicationError
from servostudio.services import identification
from servostudio.services.audit import acting_as
from servostudio.services.cancel import Cancellation, Cancelled
from servostudio.services.scan import identified


class IdentificationJobFailed(CommunicationError):
    """The server's identification job failed (its reason: a limit exceeded, the drive, the fit)."""


#: flag → service option
FLAGS = {
    "speed": "speed_rpm",
    "acceleration": "acceleration_rpm_s",
    "hold": "hold_s",
    "window": "position_window_rev",
    "current_limit": "current_limit_pct",
    "cycles": "cycles",
}
QUESTION = "identification on node {node} of bus {bus}: the motor turns both ways (shaft free, {window} rev clear)"


def register(commands: argparse._SubParsersAction) -> None:
    parser = commands.add_parser("identify", help="identify inertia and friction with the tool's own experiment")
    parser.add_argument("--bus", required=True, metavar="SPEC", help="bus spec (with --server: the server's bus)")
    parser.add_argument("--node", type=int, required=True, help="node ID 1..127")
    parser.add_argument("--device", help="device key when the node does not identify itself (--bus only)")
    parser.add_argument("--speed", type=float, metavar="RPM", help="the higher speed (default 800)")
    parser.add_argument("--acceleration", type=float, metavar="RPM_S", help="ramps, rpm/s (default 5000)")
    parser.add_argument("--hold", type=float, metavar="S", help="cruise at the higher speed, s (default 0.2)")
    parser.add_argument("--window", type=float, metavar="REV", help="position window, revolutions (default 6)")
    parser.add_argument("--current-limit", type=float, metavar="PCT", help="%% of the rated current (default 150)")
    parser.add_argument("--cycles", type=int, help="repetitions of the profile (default 2)")
    parser.add_argument(
        "--bandwidth", type=float, metavar="HZ", help="then tune the speed loop (gains, or the encoTRive's inertia)"
    )
    parser.add_argument("--yes", action="store_true", help="do not ask before starting")
    remote.add_options(parser, suppress=True)
    parser.set_defaults(handler=_run)


def request_of(args: argparse.Namespace) -> identification.IdentificationRequest:
    options: dict[str, Any] = {key: getattr(args, flag) for flag, key in FLAGS.items()}
    chosen = {key: value for key, value in options.items() if value is not None}
    return identification.IdentificationRequest(chosen, args.bandwidth)


def _run(args: argparse.Namespace) -> int:
    server = remote.Remote.of(args)
    request = request_of(args)
    with interruptible() as interrupted:
        try:
            result = _remote(args, server, request, interrupted) if server else _local(args, request, interrupted)
        except Cancelled as stopped:
            print(f"error: identification stopped ({stopped}); the axis is disabled, its objects as before",
                  file=sys.stderr)  # fmt: skip
            return EXIT_INTERRUPTED
    emit(result)
    return 0


def _question(args: argparse.Namespace, request: identification.IdentificationRequest) -> str:
    window = request.options.get("position_window_rev", identification.ExperimentOptions.position_window_rev)
    return QUESTION.format(node=args.node, bus=args.bus, window=f"{float(window):g}")


def _local(args: argparse.Namespace, request: identification.IdentificationRequest,
           interrupted: threading.Event) -> dict:  # fmt: skip
    """This command opens the bus and is the axis's live controller for its duration."""
    manager = guarded_connections(audit_log())
    try:
        with acting_as(local_actor()):
            connection = manager.open(args.bus, wait=CONNECT_WAIT)
            if not connection.link.connected:
                raise LinkDownError(f"bus {args.bus}: not connected ({connection.link.last_error or 'no answer'})")
            if args.device is None:
                identified(connection, args.node)
            drive = connection.drive(args.node, args.device)
            axis = (connection.id, args.node)
            guard = manager.motion
            with guard.live_client(local_actor()) as actor:
                guard.arm(actor, axis)
                try:
                    options = identification.check(guard, axis, request, drive)
                    confirm(args, _question(args, request))
                    cancellation = Cancellation()
                    stop_watching = forward_interrupt(interrupted, cancellation)
                    try:
                        return identification.identify(
                            guard, axis, drive, options, progress, cancellation, request.bandwidth_hz
                        )
                    finally:
                        stop_watching()
                finally:
                    guard.release(actor, axis, drive)
    finally:
        manager.close_all()


def _remote(args: argparse.Namespace, server: remote.Remote | None, request: identification.IdentificationRequest,
            interrupted: threading.Event) -> dict:  # fmt: skip
    """Through a server: the command is a live client holding the axis; the server runs the job."""
    assert server is not None
    bus = server.bus(args.bus)
    with LiveClient(server) as live, live.holding(bus, args.node):
        confirm(args, _question(args, request))
        body = {"options": dict(request.options), "bandwidth_hz": request.bandwidth_hz}
        job = live.call("POST", f"{axis_path(bus, args.node)}/identification", body)
        return _follow(live, job["id"], interrupted)


def _follow(live: LiveClient, job_id: str, interrupted: threading.Event) -> dict:
    """Until the job ends; interrupted: cancel it (the server quick-stops the axis) and wait for its end."""
    job = follow_job(live, job_id, interrupted)
    if job["state"] == "cancelled":
        raise Cancelled(f"the server's identification job {job_id} was stopped")
    if job["state"] == "failed":
        raise IdentificationJobFailed(str(job["error"]))
    return dict(job["result"])
