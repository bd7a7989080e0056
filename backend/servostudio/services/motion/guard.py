"""The motion guard: every write to a drive of the server passes here, and motion needs the axis's armed controller.

Every ``Drive`` a ``ConnectionManager`` hands out has this guard as its write gate (``drive.access.WriteGate``),
so REST object writes, drive files, restore jobs, project writes, commissioning, the terminal and the CLI all reach
the one choke point, :meth:`MotionGuard.check`, with the values the dictionary converted.  It judges what the drive
will do (``verdict.judge``: the CiA 402 transition from the drive's current state, the profile's motion objects):

- writes that *move* the axis (enable it, change what an enabled axis does, start phasing) need the caller to be
  the axis's armed controller, through its live client;
- writes that *prepare* motion (a target or the mode of a disabled axis) are refused while another client holds
  the axis;
- stopping (disable, quick stop) and everything else pass.

When a controller's client goes away, every axis it held gets a quick stop.  Each write, refused or done, and each
arm, release, take-over, enable and stop goes to the audit log (``services.audit``).
"""

from __future__ import annotations

import contextlib
import logging
import threading
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import CancelledError, Future
from typing import TYPE_CHECKING, TypeGuard

from servostudio.drive.access import Drive, DriveAccessError, PlannedWrite, WriteOutcomes
from servostudio.drive.cia402 import State
from servostudio.drive.control import quick_stop_word, read_state, set_state
from servostudio.drive.nmt import NmtCommand, NmtHeard
from servostudio.errors import Forbidden, RefusedForSafety, ServoStudioError
from servostudio.od.model import Variable
from servostudio.services.audit import SERVER, Actor, AuditLog, acting_as, axis_name, current_actor, printable
from servostudio.services.motion.control import Axis, Controllers, Holder, where
from servostudio.services.motion.jog import Motions
from servostudio.services.motion.verdict import NO_MOTION, Motion, MotionObjects, Verdict, judge, judge_nmt

if TYPE_CHECKING:
    from servostudio.services.bus.connections import ConnectionManager

log = logging.getLogger(__name__)
Publish = Callable[[dict[str, object]], None]
#: the largest batch whose old values are read before it is written: measured on the simulated drives, a read
#: first costs a single write 1.6 ms (3.3 instead of 1.6) and a 376-object restore 0.67 s (1.94 instead of 1.27)
OLD_VALUES_UP_TO = 16
#: a node an NMT command addresses: its ID, its drive (to read its state) and its NMT state as last announced
NmtTarget = tuple[int, Drive, "str | None"]
#: the user levels that may take an axis over from its controller (``services.users.levels.Level``)
TAKE_OVER_LEVELS = frozenset({"expert", "administrator"})


class TakeOverRefused(Forbidden):
    """Taking an axis over from its controller needs the Expert level."""


def _publish_nowhere(event: dict[str, object]) -> None:
    """A guard without an event hub (a CLI command) has nobody to tell."""


class BusGate:
    """The guard as the write gate of the drives of one bus: it knows which axis a drive is."""

    def __init__(self, guard: MotionGuard, bus: str) -> None:
        self.guard, self.bus = guard, bus

    def admit(self, drive: Drive, writes: Sequence[PlannedWrite]) -> WriteOutcomes:
        return self.guard.admit((self.bus, drive.node), drive, writes)


class MotionGuard:
    def __init__(self, publish: Publish = _publish_nowhere, audit: AuditLog | None = None,
                 old_values_up_to: int | None = OLD_VALUES_UP_TO) -> None:  # fmt: skip
        self.controllers = Controllers()
        self.publish = publish
        self.audit = audit if audit is not None else AuditLog(None)
        #: the largest write batch whose old values are read first for the log (None: every batch)
        self.old_values_up_to = old_values_up_to
        self._objects: dict[str, MotionObjects] = {}
        #: the quick test's jogs, moves and homing, each started through this guard (``jog``)
        self.motions = Motions(self)

    def close(self) -> None:
        """The server shuts down (after its buses closed): end the threads the guard started for it."""
        self.motions.close()

    def gate(self, bus: str) -> BusGate:
        return BusGate(self, bus)

    # ---- the choke point -------------------------------------------------------------------------------------

    def admit(self, axis: Axis, drive: Drive, writes: Sequence[PlannedWrite]) -> WriteOutcomes:
        """Judge the writes for the acting caller (refusals are logged), read the old values, and return what
        logs the outcomes once the drive answered."""
        actor = current_actor()
        try:
            verdict = self.check(actor, axis, drive, writes)
        except RefusedForSafety as refusal:
            self.audit.record(_write_entries(actor, axis, writes, [None] * len(writes), [refusal] * len(writes)))
            raise
        old_values = _read_before(drive, writes, self.old_values_up_to)
        return lambda outcomes: self._written(actor, axis, writes, verdict, old_values(), outcomes)

    def check(self, actor: Actor, axis: Axis, drive: Drive, writes: Sequence[PlannedWrite]) -> Verdict:
        """The verdict on ``writes`` to ``axis``, or the refusal: moving needs the armed controller, preparing
        motion is refused while another client holds the axis."""
        objects = self._motion_objects(drive)
        if not objects.touched_by(writes):
            return NO_MOTION
        verdict = judge(objects, _current_state(drive), writes)
        self._require(actor, axis, verdict)
        return verdict

    def admit_nmt(self, bus: str, command: NmtCommand, targets: Sequence[NmtTarget]) -> NmtHeard:
        """Judge an NMT command for every node it addresses as a write is judged (``verdict.judge_nmt``: a start
        needs the controller of an enabled axis), log a refusal and raise it (nothing is sent then); returns what
        logs the outcome once the frame is on the bus (None) or was not (the error)."""
        actor = current_actor()
        judged: list[tuple[Axis, Verdict]] = []
        for node, drive, nmt_state in targets:
            axis = (bus, node)
            verdict = judge_nmt(command, node, _current_state(drive), nmt_state)
            try:
                self._require(actor, axis, verdict)
            except RefusedForSafety as refusal:
                self.audit.record([_nmt_entry(actor, axis, command, verdict, refusal)])
                raise
            judged.append((axis, verdict))
        return lambda error: self.audit.record(
            [_nmt_entry(actor, axis, command, verdict, error) for axis, verdict in judged]
        )

    def _require(self, actor: Actor, axis: Axis, verdict: Verdict) -> None:
        if verdict.motion is Motion.MOVES:
            self.controllers.require_controller(actor, axis, verdict.reason)
        elif verdict.motion is Motion.PREPARES:
            self.controllers.require_free_or_controller(actor, axis, verdict.reason)

    def require_controller(self, actor: Actor, axis: Axis, why: str) -> None:
        """Refuse before starting something that ends in motion (walking the state machine up to enabled)."""
        self.controllers.require_controller(actor, axis, why)

    def _motion_objects(self, drive: Drive) -> MotionObjects:
        profile = drive.profile
        if profile.device not in self._objects:
            self._objects[profile.device] = MotionObjects.of(profile)
        return self._objects[profile.device]

    def _written(
        self,
        actor: Actor,
        axis: Axis,
        writes: Sequence[PlannedWrite],
        verdict: Verdict,
        old: Sequence[object],
        outcomes: Sequence[object],
    ) -> None:
        """Log the writes as the drive answered them, and the motion they started or stopped."""
        entries = _write_entries(actor, axis, writes, old, outcomes)
        if (verdict.enables or verdict.stops) and not any(isinstance(item, BaseException) for item in outcomes):
            action = "enable" if verdict.enables else "stop"
            entries.append({**_who(actor), "action": action, "axis": axis_name(*axis), "detail": verdict.reason})
        self.audit.record(entries)

    # ---- controllers -----------------------------------------------------------------------------------------

    def connect(self, user: str) -> str:
        """A new live client of ``user`` (an event socket, a CLI command)."""
        return self.controllers.connect(user)

    @contextlib.contextmanager
    def live_client(self, actor: Actor) -> Iterator[Actor]:
        """A live client for the block (a CLI command is one): ``actor`` acts through it, and it is gone afterwards.
        What it armed it must release inside the block (that quick-stops an axis still enabled)."""
        live = Actor(actor.user, actor.level, self.connect(actor.user))
        try:
            with acting_as(live):
                yield live
        finally:
            self.controllers.disconnect(live.client or "")

    def arm(self, actor: Actor, axis: Axis) -> dict[str, object]:
        """The actor's client becomes the axis's controller (refused, naming the holder, if another has it)."""
        if self.controllers.arm(actor, axis):
            self._announce(actor, axis, "armed")
        return self.control(axis)

    def release(self, actor: Actor, axis: Axis, drive: Drive) -> dict[str, object]:
        """The controller disarms the axis; an axis still enabled gets a quick stop (nobody answers for it)."""
        self.controllers.release(actor, axis)
        self._announce(actor, axis, "released")
        self._stop_if_enabled(axis, drive, f"released by {actor.user}")
        return self.control(axis)

    def request(self, actor: Actor, axis: Axis) -> dict[str, object]:
        """Ask the axis's controller, over its event socket, to release it."""
        holder = self.controllers.request(actor, axis)
        asker = {"client": actor.client, "user": actor.user}
        self.publish({"type": "control_request", "bus": axis[0], "node": axis[1], "to": holder.client, "from": asker})
        self.audit.record([{**_who(actor), "action": "request", "axis": axis_name(*axis), "detail": f"asked {holder}"}])
        return self.control(axis)

    def take_over(self, actor: Actor, axis: Axis) -> dict[str, object]:
        """An Expert's client becomes the controller; the previous holder is told, the axis keeps its state."""
        if actor.level not in TAKE_OVER_LEVELS:
            raise TakeOverRefused(f"taking {where(axis)} over needs the Expert level; {actor.user} is {actor.level}")
        previous = self.controllers.take_over(actor, axis)
        self._announce(actor, axis, "taken_over", previous)
        return self.control(axis)

    def control(self, axis: Axis) -> dict[str, object]:
        """Who holds the axis and who asked for it."""
        holder = self.controllers.holder(axis)
        asked = [item.as_dict() for item in self.controllers.requests(axis)]
        return {"bus": axis[0], "node": axis[1], "holder": holder.as_dict() if holder else None, "requests": asked}

    def controls(self) -> list[dict[str, object]]:
        """Every armed axis."""
        return [self.control(axis) for axis in sorted(self.controllers.held())]

    def _announce(self, actor: Actor, axis: Axis, event: str, previous: Holder | None = None) -> None:
        """Tell every event socket who holds the axis now, and log it."""
        shown = self.control(axis) | {"event": event, "by": {"client": actor.client, "user": actor.user}}
        self.publish({"type": "control", **shown, "previous": previous.as_dict() if previous else None})
        detail = f"from {previous}" if previous else ""
        action = {"armed": "arm", "released": "release", "taken_over": "take_over"}[event]
        self.audit.record([{**_who(actor), "action": action, "axis": axis_name(*axis), "detail": detail}])

    # ---- the holder's loss -----------------------------------------------------------------------------------

    def disconnect(self, client: str, manager: ConnectionManager) -> threading.Thread | None:
        """The client is gone: quick-stop every axis it held, on a thread of its own (returned, already started;
        None when it held none).

        Not on the event loop's executor: the socket handler calling this may itself be cancelled (server shutdown,
        a test client tearing its loop down), and the axes must stop all the same."""
        axes = self.controllers.disconnect(client)
        if not axes:
            return None
        stopper = threading.Thread(target=self._lost, args=(client, axes, manager), name=f"motion-stop {client}")
        stopper.start()
        return stopper

    def _lost(self, client: str, axes: list[Axis], manager: ConnectionManager) -> None:
        for axis in axes:
            self.publish({"type": "control", **self.control(axis), "event": "lost", "by": {"client": client}})
            try:
                self._stop_if_enabled(axis, manager.get(axis[0]).drive(axis[1]), f"client {client} went away")
            except ServoStudioError as error:
                log.error("client %s went away: quick stop of %s failed: %s", client, where(axis), error)
            except Exception:  # a bug must not leave the other axes running
                log.exception("client %s went away: quick stop of %s failed", client, where(axis))

    def quick_stop(self, axis: Axis, drive: Drive, why: str, running: bool = False) -> None:
        """Quick-stop the axis if it is enabled, as the server (a stop route, the hold-to-run watchdog).  ``running``:
        the caller just saw it run, so the quick stop is written without reading the state first (one round trip
        less between a lost keepalive and the stop; the guard still judges the write)."""
        self._stop_if_enabled(axis, drive, why, running)

    def keepalive(self, client: str, axis: Axis) -> bool:
        """A hold-to-run keepalive from the client's event socket; False when it holds no motion of the axis."""
        return self.motions.keepalive(client, axis)

    def _stop_if_enabled(self, axis: Axis, drive: Drive, why: str, running: bool = False) -> None:
        """Quick stop, done by the server itself: the axis must not run without an armed controller."""
        with acting_as(SERVER):
            if not running and read_state(drive)[0] is not State.OPERATION_ENABLED:
                return
            entry = {"action": "quick_stop", "axis": axis_name(*axis), "detail": why}
            try:
                drive.write("controlword", quick_stop_word(drive))  # at once: one write, no read of it first
                set_state(drive, State.QUICK_STOP_ACTIVE)  # and checked: the drive took it (or went further down)
            except ServoStudioError as error:
                self.audit.record([entry | {"result": "failed", "detail": f"{why}: {error}"}])
                raise
            log.warning("%s: quick stop of %s", why, where(axis))
            self.audit.record([entry | {"result": "ok"}])


def _current_state(drive: Drive) -> State | None:
    """The drive's CiA 402 state now; None when its dictionary has no status word to tell."""
    try:
        return read_state(drive)[0]
    except DriveAccessError:
        return None


def _read_before(drive: Drive, writes: Sequence[PlannedWrite], up_to: int | None) -> Callable[[], list[object]]:
    """Queue reads of the written objects ahead of the writes, so the log can say old → new; returns what gives the
    old values once the writes are done (None where unknown).  One write reads in the interactive lane, a batch in
    the bulk lane, each ahead of its writes in the node's queue; a batch larger than ``up_to`` (a restore, by
    default) is not read first: that would cost it half its time again (docs/security.md, Audit log)."""
    readable = [(position, write.variable) for position, write in enumerate(writes) if _readable(write.variable)]
    if not readable or (up_to is not None and len(writes) > up_to):
        return lambda: [None] * len(writes)
    variables = [variable for _, variable in readable]
    future = drive.submit_read_all(variables).future if len(writes) > 1 else _as_list(drive.submit_read(variables[0]))
    return lambda: _old_values(future, [position for position, _ in readable], len(writes))


def _readable(variable: Variable | None) -> TypeGuard[Variable]:
    return variable is not None and variable.access.readable


def _old_values(reads: Future, positions: list[int], count: int) -> list[object]:
    """The values read before the writes, at their writes' positions; None where the read failed or is not done
    (it always is: it was queued first)."""
    values: list[object] = [None] * count
    if reads.done() and reads.exception() is None:
        for position, value in zip(positions, reads.result(), strict=True):
            values[position] = None if isinstance(value, BaseException) else printable(value.raw)
    return values


def _as_list(single: Future) -> Future:
    """One read's future as a batch's: its outcome in a list."""
    batch: Future = Future()
    single.add_done_callback(
        lambda done: batch.set_result([CancelledError() if done.cancelled() else done.exception() or done.result()])
    )
    return batch


def _who(actor: Actor) -> dict[str, object]:
    return {"user": actor.user, "client": actor.client}


def _write_entries(
    actor: Actor, axis: Axis, writes: Sequence[PlannedWrite], old: Sequence[object], outcomes: Sequence[object]
) -> list[dict[str, object]]:
    """One ``drive_write`` entry per write, with its outcome: the value written, or the error that ended it."""
    return [
        _write_entry(actor, axis, write, before, outcome)
        for write, before, outcome in zip(writes, old, outcomes, strict=True)
    ]


def _write_entry(actor: Actor, axis: Axis, write: PlannedWrite, old: object, outcome: object) -> dict[str, object]:
    entry = {
        **_who(actor),
        "action": "drive_write",
        "axis": axis_name(*axis),
        "object": f"0x{write.index:04X},{write.sub}",
        "name": write.variable.name if write.variable is not None else None,
        "old": old,
        "new": printable(write.raw),
        "result": "ok",
    }
    if isinstance(outcome, BaseException):
        refused = isinstance(outcome, RefusedForSafety)
        entry |= {"result": "refused" if refused else "failed", "detail": str(outcome) or type(outcome).__name__}
    return entry


def _nmt_entry(
    actor: Actor, axis: Axis, command: NmtCommand, verdict: Verdict, outcome: BaseException | None
) -> dict[str, object]:
    """One ``nmt`` entry: the command sent (or refused, or failed) to one node, and the guard's reason."""
    entry = {
        **_who(actor),
        "action": "nmt",
        "axis": axis_name(*axis),
        "new": command.name.lower().replace("_", "-"),
        "result": "ok",
        "detail": verdict.reason,
    }
    if outcome is not None:
        refused = isinstance(outcome, RefusedForSafety)
        entry |= {"result": "refused" if refused else "failed", "detail": str(outcome) or type(outcome).__name__}
    return entry
