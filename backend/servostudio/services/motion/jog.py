"""The quick test's motions (manual §1.8.19): a profile-velocity jog (or the drive's own jog bits, the TTA-PRO's),
profile-position moves and homing.

One implementation for the browser, the REST API and the CLI.  A motion is started by the axis's armed controller
only (``MotionGuard.require_controller`` before anything is written, and the guard judges every write again), within
the axis's limits (``limits``, checked before anything is written), and ends ``done`` (jog time over, target reached,
homed), ``stopped`` (a quick stop: the stop route, the hold-to-run watchdog, the axis leaving Operation enabled) or
``failed`` (the drive faulted — the reason names its faults as its manual does, from the fault report through the
device profile — or did not follow the handshake).  With ``hold`` the motion runs only while its client's keepalive
arrives (``hold``).  Each change of a motion is published as a ``motion`` event.
"""

from __future__ import annotations

import contextvars
import secrets
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from servostudio.drive.access import Drive
from servostudio.drive.cia402 import State
from servostudio.drive.control import fault_report, read_state, set_state
from servostudio.drive.profiles.base import ManualMotions
from servostudio.errors import Conflict, InvalidInput, ServoStudioError
from servostudio.services.audit import Actor
from servostudio.services.motion.control import Axis, where
from servostudio.services.motion.hold import HoldWatch
from servostudio.services.motion.limits import LimitStore
from servostudio.services.motion.units import rpm_to_speed, units_per_revolution

if TYPE_CHECKING:
    from servostudio.services.motion.guard import MotionGuard

#: modes of operation (0x6060) of the quick test
PROFILE_POSITION, PROFILE_VELOCITY, HOMING = 1, 3, 6
ENABLED = 0x000F  # control word: Enable operation
NEW_SET_POINT, RELATIVE = 0x0010, 0x0040  # PP: bit 4 (also HM: start homing), bit 6
TARGET_REACHED, ACKNOWLEDGED, HOMING_ERROR = 1 << 10, 1 << 12, 1 << 13  # status word bits (HM: bit 12 = attained)
#: states of a drive that faulted: a motion that ends in one of them failed, and the fault names why
FAULTED = (State.FAULT_REACTION_ACTIVE, State.FAULT)
#: seconds between two status reads of a running motion
POLL_PERIOD = 0.02
#: seconds the drive has to acknowledge a new set-point (PP) before the move counts as failed
ACKNOWLEDGE_TIMEOUT = 1.0
#: the speed of a move that names none, in rpm (capped by the axis's limit)
DEFAULT_MOVE_RPM = 60.0

Finished = Callable[[int], "tuple[str, str | None] | None"]  # status word → (end state, reason), None: running


class MotionRunning(Conflict):
    """The axis is already running a quick-test motion: stop it first."""


class MotionFailed(Conflict):
    """The drive did not follow the quick test's handshake (a set-point not acknowledged in time)."""


@dataclass
class Run:
    """One motion of one axis, as the REST answers and ``motion`` events show it."""

    axis: Axis
    kind: str
    client: str
    hold: bool
    request: dict[str, object]
    drive: Drive = field(repr=False)
    id: str = field(default_factory=lambda: secrets.token_hex(6))
    state: str = "running"
    reason: str | None = None
    started: float = field(default_factory=time.time)
    ended: float | None = None
    last_keepalive: float | None = None
    position: int | None = None
    statusword: int | None = None
    since: float = field(default_factory=time.monotonic, repr=False)

    def as_dict(self) -> dict[str, object]:
        return {
            "motion": self.id,
            "bus": self.axis[0],
            "node": self.axis[1],
            "kind": self.kind,
            "state": self.state,
            "reason": self.reason,
            "hold": self.hold,
            "client": self.client,
            "request": self.request,
            "started": self.started,
            "ended": self.ended,
            "last_keepalive": self.last_keepalive,
            "position": self.position,
            "statusword": self.statusword,
        }


class Motions:
    """The running and last motion of each axis."""

    def __init__(self, guard: MotionGuard) -> None:
        self.guard = guard
        self.limits = LimitStore()
        self.holds = HoldWatch(self._expired)
        self._lock = threading.Lock()
        self._runs: dict[Axis, Run] = {}

    def close(self) -> None:
        """The server shuts down: end the hold-to-run watchdog's thread (``HoldWatch.close``)."""
        self.holds.close()

    # ---- the three motions ------------------------------------------------------------------------------------

    def jog(self, actor: Actor, axis: Axis, drive: Drive, velocity: float, seconds: float | None, hold: bool) -> dict:
        """Profile velocity at ``velocity`` rpm for ``seconds`` (None: for as long as the hold lasts)."""
        self._require(actor, axis, "a jog")
        limits = self.limits.of(axis)
        limits.check_velocity(axis, velocity)
        if seconds is None and not hold:
            raise InvalidInput("a jog needs 'seconds' or 'hold': it must end by itself or when released")
        if seconds is not None:
            limits.check_seconds(axis, seconds)
        writes, trigger = _jog_writes(drive, velocity)
        request = {"velocity": velocity, "seconds": seconds}
        run = self._begin(actor, axis, drive, "jog", hold, request)
        return self._launch(run, writes, trigger, self._jog_finished(run, seconds))

    def move(
        self,
        actor: Actor,
        axis: Axis,
        drive: Drive,
        distance: float,
        absolute: bool,
        velocity: float | None,
        hold: bool,
    ) -> dict:
        """Profile position: ``distance`` user position units from here, or to ``distance`` (``absolute``)."""
        self._require(actor, axis, "a move")
        limits = self.limits.of(axis)
        speed = velocity if velocity is not None else min(DEFAULT_MOVE_RPM, limits.velocity_rpm)
        limits.check_velocity(axis, speed)
        if speed <= 0:
            raise InvalidInput(f"a move needs a positive velocity, not {speed} rpm")
        per_revolution = units_per_revolution(drive)
        target = round(distance)
        travel = target - int(drive.read("position_actual").raw) if absolute else target
        limits.check_distance(axis, travel / per_revolution)
        writes, trigger, finished = _move_steps(drive, target, absolute, speed)
        request = {"distance": distance, "absolute": absolute, "velocity": speed}
        run = self._begin(actor, axis, drive, "move", hold, request)
        return self._launch(run, writes, trigger, finished)

    def home(
        self, actor: Actor, axis: Axis, drive: Drive, method: int, hold: bool, velocity: float | None = None
    ) -> dict:
        """Homing with ``method`` (0x6098), at the drive's homing speeds or ``velocity`` rpm (slow: a quarter)."""
        self._require(actor, axis, "homing")
        methods = drive.profile.homing_methods
        if method not in methods:
            known = ", ".join(str(number) for number in sorted(methods))
            raise InvalidInput(f"{drive.profile.device} has no homing method {method}; it has {known}")
        if velocity is not None:
            self.limits.of(axis).check_velocity(axis, velocity)
        writes, trigger, finished = _homing_steps(drive, method, velocity)
        run = self._begin(actor, axis, drive, "home", hold, {"method": method, "velocity": velocity})
        return self._launch(run, writes, trigger, finished)

    # ---- stop, keepalive, what runs ---------------------------------------------------------------------------

    def stop(self, actor: Actor, axis: Axis, drive: Drive) -> dict:
        """Quick stop, whoever asks: stopping an axis never needs its controller."""
        run = self._current(axis)
        why = f"stopped by {actor.user}"
        if run is not None:
            self._finish(run, "stopped", why)
        self.guard.quick_stop(axis, drive, why)
        if run is None:
            return {"motion": None, "bus": axis[0], "node": axis[1], "state": "stopped", "reason": why}
        return run.as_dict()

    def keepalive(self, client: str, axis: Axis) -> bool:
        """The client's hold-to-run keepalive for the axis; False when it holds no motion there."""
        if self.holds.keepalive(client, axis) is None:
            return False
        run = self._current(axis)
        if run is not None and run.client == client:
            run.last_keepalive = time.time()
        return True

    def current(self, axis: Axis) -> dict | None:
        """The axis's running motion, else its last one (None: none since the server started)."""
        with self._lock:
            run = self._runs.get(axis)
        return run.as_dict() if run else None

    def _current(self, axis: Axis) -> Run | None:
        with self._lock:
            run = self._runs.get(axis)
        return run if run is not None and run.state == "running" else None

    # ---- running one -----------------------------------------------------------------------------------------

    def _require(self, actor: Actor, axis: Axis, what: str) -> None:
        """Before anything is read or written: only the armed controller, and one motion at a time."""
        self.guard.require_controller(actor, axis, f"{what} of {where(axis)}")
        running = self._current(axis)
        if running is not None:
            raise MotionRunning(f"{where(axis)} is running {running.kind} {running.id}: stop it first")

    def _begin(self, actor: Actor, axis: Axis, drive: Drive, kind: str, hold: bool, request: dict) -> Run:
        run = Run(axis, kind, actor.client or "", hold, request, drive)
        with self._lock:
            running = self._runs.get(axis)
            if running is not None and running.state == "running":
                raise MotionRunning(f"{where(axis)} is running {running.kind} {running.id}: stop it first")
            self._runs[axis] = run
        if hold:
            self.holds.hold(axis, run.client)
        return run

    def _launch(
        self, run: Run, writes: list[tuple[str, int]], trigger: Callable[[Drive], None] | None, finished: Finished
    ) -> dict:
        """Write the motion's objects, enable the axis, trigger it; then follow it on a thread of its own."""
        try:
            for name, value in writes:
                run.drive.write(name, value)
            set_state(run.drive, State.OPERATION_ENABLED)
            if trigger is not None:
                trigger(run.drive)
        except ServoStudioError as error:
            self._finish(run, "failed", str(error))
            if run.hold or trigger is not None:
                self._stop_quietly(run, f"{run.kind} could not start: {error}")
            raise
        if run.state != "running":  # ended while it started (its hold expired, a stop): it must not run on
            self._stop_quietly(run, f"{run.kind} {run.id} ended while it started: {run.reason}")
            return run.as_dict()
        self.guard.publish({"type": "motion", **run.as_dict()})
        context = contextvars.copy_context()  # the controller's: what the motion writes later, it writes
        follower = threading.Thread(target=context.run, args=(self._follow, run, finished), daemon=True)
        follower.name = f"motion {run.id}"
        follower.start()
        return run.as_dict()

    def _follow(self, run: Run, finished: Finished) -> None:
        """Read the status word until the motion ends (or something else ended it)."""
        while run.state == "running":
            time.sleep(POLL_PERIOD)
            try:
                self._check(run, finished)
            except ServoStudioError as error:
                self._finish(run, "failed", str(error))
                self._stop_quietly(run, f"{run.kind} failed: {error}")
        self._read_position(run)

    def _check(self, run: Run, finished: Finished) -> None:
        state, statusword = read_state(run.drive)
        run.statusword = statusword
        if run.state != "running":
            return
        if state is not State.OPERATION_ENABLED:
            self._finish(run, *_left_operation_enabled(run.drive, state))
            return
        outcome = finished(statusword)
        if outcome is not None:
            self._finish(run, *outcome)

    def _jog_finished(self, run: Run, seconds: float | None) -> Finished:
        """A jog with a duration ends when it is over: target velocity 0, the axis stays enabled at standstill."""

        def over(statusword: int) -> tuple[str, str | None] | None:
            if seconds is None or time.monotonic() - run.since < seconds:
                return None
            _end_jog(run.drive)
            return "done", None

        return over

    def _finish(self, run: Run, state: str, reason: str | None) -> bool:
        """End the run once (the first ending wins); tell every event socket."""
        with self._lock:
            if run.state != "running":
                return False
            run.state, run.reason, run.ended = state, reason, time.time()
        self.holds.drop(run.axis)
        self.guard.publish({"type": "motion", **run.as_dict()})
        return True

    def _read_position(self, run: Run) -> None:
        try:
            run.position = int(run.drive.read("position_actual").raw)
        except ServoStudioError:
            return
        self.guard.publish({"type": "motion", **run.as_dict()})

    def _expired(self, axis: Axis, client: str, last: float) -> None:
        """The watchdog: no keepalive from the holder in time — quick stop, on a thread of its own."""
        run = self._current(axis)
        if run is None or run.client != client:
            return
        silent_ms = (time.monotonic() - last) * 1000
        why = f"hold-to-run: no keepalive from client {client} for {silent_ms:.0f} ms"
        if self._finish(run, "stopped", why):
            stopper = threading.Thread(target=self._stop_quietly, args=(run, why, True), name=f"hold-stop {run.id}")
            stopper.start()

    def _stop_quietly(self, run: Run, why: str, running: bool = False) -> None:
        """A quick stop nobody waits for: a failure is in the audit log and the server's log (``guard``)."""
        try:
            self.guard.quick_stop(run.axis, run.drive, why, running)
        except ServoStudioError as error:
            run.reason = f"{why}; the quick stop failed: {error}"


def _left_operation_enabled(drive: Drive, state: State | None) -> tuple[str, str]:
    """How a motion ends when its axis is no longer enabled: ``failed`` with the drive's faults when it faulted (a
    following error, the TTA-PRO's homing time-out), else ``stopped`` (a stop, a lost controller)."""
    if state in FAULTED:
        return "failed", f"the drive faulted: {_faults_named(drive)}"
    return "stopped", f"the axis left Operation enabled ({state.value if state else '?'})"


def _faults_named(drive: Drive) -> str:
    """The active faults in the manual's words (``drive.control.fault_report``: the device profile decodes the
    drive's error words or error code), else the CiA 402 error text, else the status word."""
    try:
        report = fault_report(drive)
    except ServoStudioError as error:
        return f"its fault report could not be read ({error})"
    names = "; ".join(fault.name for fault in report.faults)
    return names or report.error_text or f"status word 0x{report.statusword:04X}"


def _jog_writes(drive: Drive, velocity: float) -> tuple[list[tuple[str, int]], Callable[[Drive], None] | None]:
    """What starts a jog at ``velocity`` rpm. CiA 402: profile velocity at that target velocity. A drive with jog
    bits (``DeviceProfile.jog_bits``, the TTA-PRO's CW8 / CW9): its jog speed in rpm, then, once enabled, the bit of
    the direction, which the drive jogs on while it stays set (0 rpm: no bit, the axis stays at standstill)."""
    bits = drive.profile.jog_bits
    if bits is None:
        return [("modes_of_operation", PROFILE_VELOCITY), ("target_velocity", rpm_to_speed(drive, velocity))], None
    direction = 0 if velocity == 0 else bits[0] if velocity > 0 else bits[1]
    speed = max(1, round(abs(velocity)))
    return [("jog_speed", speed)], lambda enabled: _start_jog(enabled, direction)


def _start_jog(drive: Drive, direction: int) -> None:
    """Set the direction's jog bit (the drive jogs while it stays set)."""
    drive.write("controlword", _jog_word(drive) | direction)


def _jog_word(drive: Drive) -> int:
    """The control word going out without the jog bits."""
    plus, minus = drive.profile.jog_bits or (0, 0)
    return int(drive.read("controlword").raw) & ~(plus | minus)


def _end_jog(drive: Drive) -> None:
    """A timed jog is over: target velocity 0, or the jog bits cleared (the drive ramps down, stays enabled)."""
    if drive.profile.jog_bits is None:
        drive.write("target_velocity", 0)
    else:
        drive.write("controlword", _jog_word(drive))


Writes = list[tuple[str, int]]
Steps = tuple[Writes, Callable[[Drive], None], Finished]


def _move_steps(drive: Drive, target: int, absolute: bool, rpm: float) -> Steps:
    """What a move writes, what triggers it, when it is over. CiA 402: profile position, a new set-point. A drive
    with manual motions (the TTA-PRO): its set point and speed in rpm, then a toggle of the move's control bit."""
    manual = drive.profile.manual_motions
    if manual is None:
        writes = [
            ("modes_of_operation", PROFILE_POSITION),
            ("profile_velocity", rpm_to_speed(drive, rpm)),
            ("target_position", target),
        ]
        return writes, _set_point(0 if absolute else RELATIVE), _position_finished
    writes = [(manual.speed, max(1, round(rpm))), (manual.target, target)]
    bit = manual.absolute if absolute else manual.relative
    return writes, _manual_command(manual, bit, toggle=True), _manual_done(manual.position_reached)


def _homing_steps(drive: Drive, method: int, rpm: float | None) -> Steps:
    """CiA 402: homing mode with the method (0x6098), its speeds (slow: a quarter). Manual motions: the method is
    the homing configuration (TTA-PRO: PNU 766), at the manual-motion speed in rpm, started by a rising edge."""
    manual = drive.profile.manual_motions
    if manual is None:
        writes: Writes = [("modes_of_operation", HOMING), ("homing_method", method)]
        if rpm is not None:
            fast = max(1, rpm_to_speed(drive, abs(rpm)))
            writes += [("homing_speed_fast", fast), ("homing_speed_slow", max(1, fast // 4))]
        return writes, _set_point(0), _homing_finished
    writes = [(manual.homing_configuration, method)]
    if rpm is not None:
        writes.append((manual.speed, max(1, round(abs(rpm)))))
    return writes, _manual_command(manual, manual.homing, toggle=False), _manual_done(manual.home_found)


def _manual_command(manual: ManualMotions, bit: int, toggle: bool) -> Callable[[Drive], None]:
    """An edge of ``bit`` (a toggle, or a rising edge: cleared first when set), held until the drive acknowledges
    it by toggling its acknowledge status bit; the motion's status is judged only after that."""

    def trigger(drive: Drive) -> None:
        before = int(drive.read("statusword").raw) & manual.acknowledge
        word = int(drive.read("controlword").raw)
        if not toggle and word & bit:
            drive.write("controlword", word & ~bit)
        drive.write("controlword", word ^ bit if toggle else word | bit)
        _wait_for(drive, lambda statusword: statusword & manual.acknowledge != before, "acknowledge the command")

    return trigger


def _manual_done(status_bit: int) -> Finished:
    """Done once the drive reports it (position reached, home found) after it acknowledged the command."""

    def finished(statusword: int) -> tuple[str, str | None] | None:
        return ("done", None) if statusword & status_bit else None

    return finished


def _set_point(bits: int) -> Callable[[Drive], None]:
    """PP: a new set-point (bit 4 rising, bit 6 relative), held until acknowledged; HM: start homing (bit 4)."""

    def trigger(drive: Drive) -> None:
        drive.write("controlword", ENABLED | bits)
        _wait_for(drive, lambda statusword: not statusword & ACKNOWLEDGED, "clear bit 12 after control word bit 4 = 0")
        drive.write("controlword", ENABLED | NEW_SET_POINT | bits)

    return trigger


def _wait_for(drive: Drive, ready: Callable[[int], bool], what: str) -> None:
    """Poll the status word until ``ready``: a rising edge of bit 4 needs the drive to have seen it low first."""
    deadline = time.monotonic() + ACKNOWLEDGE_TIMEOUT
    while not ready(int(drive.read("statusword").raw)):
        if time.monotonic() > deadline:
            raise MotionFailed(f"node {drive.node}: the drive did not {what} within {ACKNOWLEDGE_TIMEOUT:g} s")
        time.sleep(0.002)


def _position_finished(statusword: int) -> tuple[str, str | None] | None:
    """PP: done once the drive acknowledged the set-point and reached the target."""
    if statusword & ACKNOWLEDGED and statusword & TARGET_REACHED:
        return "done", None
    return None


def _homing_finished(statusword: int) -> tuple[str, str | None] | None:
    """HM: bit 13 homing error, bits 12 + 10 homing attained."""
    if statusword & HOMING_ERROR:
        return "failed", "the drive reports a homing error (status word bit 13): method not possible here"
    if statusword & ACKNOWLEDGED and statusword & TARGET_REACHED:
        return "done", None
    return None
