"""The quick test from the command line: ``servostudio jog`` and ``servostudio home`` (JSON on stdout).

    servostudio jog  --bus SPEC --node N (--velocity V --seconds S | --move DISTANCE [--absolute] [--velocity V])
    servostudio home --bus SPEC --node N --method M [--velocity V]
    (each also with --server URL [--token TOKEN]: --bus then names the server's bus, by id or spec)

The command is the axis's live controller: it arms the axis, runs the motion and waits for its end, then releases
the axis (a quick stop if it is still enabled).  Ctrl-C, SIGTERM or SIGHUP quick-stops the motion.  Through a
server the motion is hold-to-run: the command's live client (``cli.liveclient``) sends the keepalive while it runs,
so a command that is killed or hangs stops the axis within 200 ms of its last keepalive.  The answer is the motion
as ``GET …/motion`` gives it; a motion that did not end ``done`` exits 3 (refused_for_safety) after printing it.
"""

from __future__ import annotations

import argparse
import threading
from collections.abc import Callable
from typing import Any

from servostudio.cli import remote
from servostudio.cli.audit import audit_log, guarded_connections, local_actor
from servostudio.cli.jobrun import interruptible
from servostudio.cli.liveclient import LiveClient, axis_path
from servostudio.cli.output import emit
from servostudio.drive.access import Drive
from servostudio.errors import InvalidInput, RefusedForSafety
from servostudio.services.audit import acting_as
from servostudio.services.motion import MotionGuard
from servostudio.services.scan import identified

CONNECT_WAIT = 3.0
#: seconds between two looks at a running motion
POLL = 0.05
Start = Callable[[Callable[[str, dict[str, Any]], dict]], dict]  # (route, body) → the motion's answer


class MotionDidNotFinish(RefusedForSafety):
    """The motion was stopped or failed (the printed answer says why)."""


def register(commands: argparse._SubParsersAction) -> None:
    jog = _parser(commands, "jog", "jog in profile velocity, or move in profile position (--move)", _jog)
    jog.add_argument("--velocity", type=float, help="rpm (jog: required; move: default 60)")
    jog.add_argument("--seconds", type=float, help="how long to jog")
    jog.add_argument("--move", type=float, metavar="DISTANCE", help="move by DISTANCE user position units")
    jog.add_argument("--absolute", action="store_true", help="--move to the position DISTANCE")
    home = _parser(commands, "home", "home the axis with a homing method (0x6098)", _home)
    home.add_argument("--method", type=int, required=True, help="homing method, e.g. 35 (current position)")
    home.add_argument("--velocity", type=float, help="rpm of the switch search (default: the drive's)")


def _parser(
    commands: argparse._SubParsersAction, name: str, help_text: str, request: Callable[[argparse.Namespace], tuple]
) -> argparse.ArgumentParser:
    parser = commands.add_parser(name, help=help_text)
    parser.add_argument("--bus", required=True, metavar="SPEC", help="bus spec (with --server: the server's bus)")
    parser.add_argument("--node", type=int, required=True, help="node ID 1..127")
    remote.add_options(parser, suppress=True)
    parser.set_defaults(handler=lambda args: _run(args, *request(args)))
    return parser


def _jog(args: argparse.Namespace) -> tuple[str, dict[str, Any]]:
    if args.move is not None:
        return "move", {"distance": args.move, "absolute": args.absolute, "velocity": args.velocity}
    if args.velocity is None or args.seconds is None:
        raise InvalidInput("jog needs --velocity V --seconds S, or --move DISTANCE [--absolute]")
    return "jog", {"velocity": args.velocity, "seconds": args.seconds}


def _home(args: argparse.Namespace) -> tuple[str, dict[str, Any]]:
    return "home", {"method": args.method, "velocity": args.velocity}


def _run(args: argparse.Namespace, route: str, body: dict[str, Any]) -> int:
    server = remote.Remote.of(args)
    with interruptible() as interrupted:
        ended = (_remote if server else _local)(args, server, route, body, interrupted)
    emit(ended)
    if ended["state"] != "done":
        raise MotionDidNotFinish(f"the {ended.get('kind') or route} ended {ended['state']}: {ended.get('reason')}")
    return 0


def _wait(current: Callable[[], dict | None], stop: Callable[[], dict], interrupted: threading.Event) -> dict:
    """Until the motion ends; interrupted: quick stop, and the motion as it ended."""
    while not interrupted.wait(POLL):
        motion = current()
        if motion is not None and motion["state"] != "running":
            return motion
    return stop()


# ---- here: the command opens the bus -----------------------------------------------------------------------------


def _local(
    args: argparse.Namespace, _: remote.Remote | None, route: str, body: dict[str, Any], interrupted: threading.Event
) -> dict:
    manager = guarded_connections(audit_log())
    try:
        with acting_as(local_actor()):
            connection = manager.open(args.bus, wait=CONNECT_WAIT)
            identified(connection, args.node)
            drive = connection.drive(args.node)
            return _local_motion(manager.motion, (connection.id, args.node), drive, route, body, interrupted)
    finally:
        manager.close_all()


def _local_motion(
    guard: MotionGuard, axis: tuple[str, int], drive: Drive, route: str, body: dict, interrupted: threading.Event
) -> dict:
    """This command is the live controller: arm, run, wait, release (a quick stop if still enabled)."""
    motions = guard.motions
    with guard.live_client(local_actor()) as actor:
        guard.arm(actor, axis)
        try:
            if route == "jog":
                motions.jog(actor, axis, drive, body["velocity"], body["seconds"], hold=False)
            elif route == "move":
                motions.move(actor, axis, drive, body["distance"], body["absolute"], body["velocity"], hold=False)
            else:
                motions.home(actor, axis, drive, body["method"], hold=False, velocity=body["velocity"])
            return _wait(lambda: motions.current(axis), lambda: motions.stop(actor, axis, drive), interrupted)
        finally:
            guard.release(actor, axis, drive)


# ---- through a server: the command is a live client of it --------------------------------------------------------


def _remote(
    args: argparse.Namespace,
    server: remote.Remote | None,
    route: str,
    body: dict[str, Any],
    interrupted: threading.Event,
) -> dict:
    assert server is not None
    bus = server.bus(args.bus)
    path = f"{axis_path(bus, args.node)}/motion"
    with LiveClient(server) as live, live.holding(bus, args.node):
        live.call("POST", f"{path}/{route}", body | {"hold": True})
        return _wait(lambda: live.call("GET", path), lambda: live.call("POST", f"{path}/stop"), interrupted)
