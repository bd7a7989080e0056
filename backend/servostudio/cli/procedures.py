"""Procedures from the command line (issue #13 item 6, pinned; JSON on stdout):

    servostudio autophase   --bus SPEC --node N [--yes]
    servostudio motorphase  --bus SPEC --node N [--yes]
    servostudio currentloop --bus SPEC --node N [--inductance MH] [--regulator high|low] [--yes]
    servostudio autotune    --bus SPEC --node N --bandwidth 50|75|100 [--filter standard|anti-resonance|max-stiffness]
                            [--speed-filter auto|0.5|1|2] [--mode min-following-error|min-overshoot] [--yes]
    (each also with --server URL [--token TOKEN]: --bus then names the server's bus, by id or spec)

The answer is the procedure service's result, the same JSON a job ends with (docs/commissioning.md). Without
``--yes`` the command asks on the terminal before anything is written; without a terminal it refuses (exit 3). With
``--bus`` the command opens the bus itself and is the axis's live controller for its duration (it arms the axis
through the in-process motion guard and releases it at the end); with ``--server`` it is a live client of the server
(``cli.liveclient``). Ctrl-C, SIGTERM or SIGHUP aborts the procedure (the drive is left disabled, the gains as
before) and exits 130 after printing the aborted result. Exit codes: 3 refused (preconditions, options, no
confirmation — nothing written), 4 unknown node or procedure, 5 the procedure failed on the drive (its fault and the
likely cause on stderr) or the bus failed.
"""

from __future__ import annotations

import argparse
import sys
import threading
from typing import Any

from servostudio.cli import remote
from servostudio.cli.audit import audit_log, guarded_connections, local_actor
from servostudio.cli.jobrun import follow_job, forward_interrupt, interruptible, print_progress
from servostudio.cli.liveclient import LiveClient, axis_path
from servostudio.cli.output import emit
from servostudio.drive.access import Drive
from servostudio.drive.link import LinkDownError
from servostudio.errors import NotFound, RefusedForSafety
from servostudio.services.audit import acting_as
from servostudio.services.cancel import Cancellation
from servostudio.services.motion import MotionGuard
from servostudio.services.procedures import ProcedureFailed, ProcedureRequest, ProcedureService, description_of
from servostudio.services.scan import identified

CONNECT_WAIT = 3.0
EXIT_INTERRUPTED = 130
#: command → procedure (semantic name)
COMMANDS = {
    "autophase": ("auto_phasing", "auto-phasing: finds pole pairs, phase order and sensor offset (turns the motor)"),
    "motorphase": ("motor_phasing", "motor phasing: finds the sensor offset with known pole pairs (turns the motor)"),
    "currentloop": ("current_loop", "current-loop calculation: current gains and limits from the motor data"),
    "autotune": ("auto_tuning", "auto-tuning: identifies the mechanics and computes the gains (turns the motor)"),
}


class ConfirmationNeeded(RefusedForSafety):
    """No ``--yes`` and no terminal to ask on, or the answer was no: nothing was written."""


def register(commands: argparse._SubParsersAction) -> None:
    for command, (procedure, help_text) in COMMANDS.items():
        parser = commands.add_parser(command, help=help_text)
        parser.add_argument("--bus", required=True, metavar="SPEC", help="bus spec (with --server: the server's bus)")
        parser.add_argument("--node", type=int, required=True, help="node ID 1..127")
        parser.add_argument("--device", help="device key when the node does not identify itself (--bus only)")
        parser.add_argument("--yes", action="store_true", help="do not ask before starting")
        remote.add_options(parser, suppress=True)
        parser.set_defaults(handler=lambda args, name=procedure: _run(args, name), procedure=procedure)
    _options(commands.choices)


def _options(parsers: dict[str, argparse.ArgumentParser]) -> None:
    autotune, currentloop = parsers["autotune"], parsers["currentloop"]
    autotune.add_argument("--bandwidth", required=True, choices=("50", "75", "100"), help="speed-loop bandwidth, Hz")
    autotune.add_argument("--filter", choices=("standard", "anti-resonance", "max-stiffness"), default="standard")
    autotune.add_argument("--speed-filter", choices=("auto", "0.5", "1", "2"), default="auto", help="ms, or auto")
    autotune.add_argument("--mode", choices=("min-following-error", "min-overshoot"), default="min-following-error")
    currentloop.add_argument("--inductance", type=float, metavar="MH", help="phase-to-phase inductance, mH")
    currentloop.add_argument("--regulator", choices=("high", "low"), help="current regulator type (500 / 250 Hz)")
    for name in ("autophase", "autotune"):
        parsers[name].add_argument("--no-verify", action="store_true", help="skip the verification")


def request_of(args: argparse.Namespace) -> ProcedureRequest:
    """The service's request from the command's flags."""
    options: dict[str, Any] = {}
    if args.procedure == "auto_tuning":
        options = {
            "bandwidth": args.bandwidth,
            "filter": args.filter,
            "speed_filter": args.speed_filter,
            "mode": args.mode,
        }
    elif args.procedure == "current_loop":
        options = {"inductance_mh": args.inductance, "regulator": args.regulator}
    return ProcedureRequest(
        {key: value for key, value in options.items() if value is not None}, not getattr(args, "no_verify", False)
    )


def _run(args: argparse.Namespace, name: str) -> int:
    server = remote.Remote.of(args)
    with interruptible() as interrupted:
        result = (_remote if server else _local)(args, server, name, request_of(args), interrupted)
    emit(result)
    if result.get("status") == "aborted":
        print(f"error: {name.replace('_', '-')} aborted; the drive is disabled, the gains as before", file=sys.stderr)
        return EXIT_INTERRUPTED
    return 0


def confirm(args: argparse.Namespace, what: str) -> None:
    """Ask on the terminal unless ``--yes``; refuse without a terminal."""
    if args.yes:
        return
    if not sys.stdin.isatty():
        raise ConfirmationNeeded(f"{what}: confirm with --yes (no terminal to ask on; nothing was written)")
    print(f"{what}. Start it? [y/N] ", end="", file=sys.stderr, flush=True)
    if sys.stdin.readline().strip().lower() not in ("y", "yes"):
        raise ConfirmationNeeded(f"{what}: not confirmed; nothing was written")


def _question(args: argparse.Namespace, label: str, moves: bool) -> str:
    warning = ": the motor will turn (shaft free, one revolution safe, limit switches clear)" if moves else ""
    return f"{label} on node {args.node} of bus {args.bus}{warning}"


# ---- here: the command opens the bus -----------------------------------------------------------------------------


def _local(
    args: argparse.Namespace,
    _: remote.Remote | None,
    name: str,
    request: ProcedureRequest,
    interrupted: threading.Event,
) -> dict:
    manager = guarded_connections(audit_log())
    try:
        with acting_as(local_actor()):
            connection = manager.open(args.bus, wait=CONNECT_WAIT)
            if not connection.link.connected:
                raise LinkDownError(f"bus {args.bus}: not connected ({connection.link.last_error or 'no answer'})")
            if args.device is None:
                identified(connection, args.node)
            drive = connection.drive(args.node, args.device)
            return _controlled(manager.motion, (connection.id, args.node), drive, args, name, request, interrupted)
    finally:
        manager.close_all()


def _controlled(
    guard: MotionGuard, axis: tuple[str, int], drive: Drive, args: argparse.Namespace, name: str,
    request: ProcedureRequest, interrupted: threading.Event,
) -> dict:  # fmt: skip
    """This command is the live controller for its duration: arm, check, confirm, run, release."""
    service = ProcedureService()
    description = description_of(drive, name)
    with guard.live_client(local_actor()) as actor:
        guard.arm(actor, axis)
        try:
            writes = service.check(guard, axis, drive, name, request)
            confirm(args, _question(args, description.label, description.moves))
            cancellation = Cancellation()
            watcher = forward_interrupt(interrupted, cancellation)
            try:
                return service.run(guard, axis, drive, name, request, print_progress, cancellation, writes)
            finally:
                watcher()
        finally:
            guard.release(actor, axis, drive)


# ---- through a server: the command is a live client of it --------------------------------------------------------


def _remote(
    args: argparse.Namespace, server: remote.Remote | None, name: str, request: ProcedureRequest,
    interrupted: threading.Event,
) -> dict:  # fmt: skip
    assert server is not None
    bus = server.bus(args.bus)
    path = f"{axis_path(bus, args.node)}/procedures"
    listed = {item["name"]: item for item in server.call("GET", path)}
    if name not in listed:
        raise NotFound(
            f"node {args.node} of bus {bus} has no procedure {name!r} (it has {', '.join(listed) or 'none'})"
        )
    body = {"options": dict(request.options), "verify": request.verify}
    with LiveClient(server) as live, live.holding(bus, args.node):
        confirm(args, _question(args, str(listed[name]["label"]), bool(listed[name]["moves"])))
        job = live.call("POST", f"{path}/{name}", body)
        return _follow(live, job["id"], interrupted)


def _follow(live: LiveClient, job_id: str, interrupted: threading.Event) -> dict:
    """Until the job ends; interrupted: cancel it (= abort) and wait for its end."""
    job = follow_job(live, job_id, interrupted)
    if job["state"] == "failed":
        raise ProcedureFailed(str(job["error"]))
    return dict(job["result"])
