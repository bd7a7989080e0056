"""The identification experiment (docs/identification.md § Experiment): the axis runs back and forth between
positions either side of its start in profile position (the encoTRive has no torque mode; the drive's own position
loop and trajectory keep the axis within its targets whatever the host's timing), while synchronous TPDOs at the
server's SYNC record shaft angle, speed and current.

Each cycle is four moves, ``+X(v) → −X(v)`` at speed v, then ``+X(v·LOW_SHARE) → −X(v·LOW_SHARE)``, X chosen so
that each move between opposite targets cruises ``hold_s`` at its speed (the low speed twice as long): the two speeds
per direction separate viscous from Coulomb friction, both directions Coulomb friction from a constant load, and the
ramps give the inertia. The largest target plus a margin for the following error must fit the position window (else
refused before anything is written).

Safety, as the frequency response has it: the speed limit 0x607F and the current limit 0x6073 are set for the run;
the axis's angle, speed and current are read every ``WATCH_SECONDS`` and a value beyond the position window, 1.25 ×
the speed or 1.1 × the current limit quick-stops the axis and ends the run (``LimitExceeded`` names which). The
drive is disabled and every object the run changed is written back whatever happens.
"""

from __future__ import annotations

import contextvars
import threading
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass
from typing import Any

from servostudio.drive.access import Drive
from servostudio.drive.cia402 import State
from servostudio.drive.control import set_state
from servostudio.errors import InvalidInput, RefusedForSafety
from servostudio.services.cancel import Cancellation
from servostudio.services.identification.estimator import Record
from servostudio.services.identification.units import TWO_PI, Scales, scales
from servostudio.services.procedures.run import disable, fault_cause, read_values, restore
from servostudio.services.scope import Capture, CaptureDefinition, DriveIdentity, capture

MODE_PP = 1
LOW_SHARE = 0.3
#: the low speed cruises this many times longer (its travel is small; it carries half of the viscous signal)
LOW_HOLDS = 2.0
PERIOD_US = 1000.0
WATCH_SECONDS = 0.01
#: the standstill recorded after the last move, s
END_S = 0.05
#: the capture runs this much longer than the ideal moves (its start waits for the TPDOs, a move for its arrival)
CAPTURE_MARGIN_S, CAPTURE_STRETCH = 0.3, 1.3
SPEED_MARGIN, CURRENT_MARGIN = 1.25, 1.1
#: the targets' margin for the position loop's lag (the window check stays the last resort)
FOLLOWING_MARGIN = 1.2
#: a move has arrived within this share of a revolution of its target and below this speed
ARRIVED, STANDSTILL_RAD_S = 0.01, 1.0
#: a move that has not arrived after this many times its ideal duration plus MOVE_TIMEOUT_S ends all the same
MOVE_TIMEOUT_FACTOR, MOVE_TIMEOUT_S = 3.0, 2.0
#: control word: enable operation + new set-point + change at once (absolute target), then without the new set-point
NEW_SET_POINT, ENABLED_AT_ONCE = 0x3F, 0x2F
FAULT_BIT = 0x08
QUICK_STOP = 0x02
CHANNELS = ("position_actual", "velocity_actual", "current_actual")
SAVED = ("modes_of_operation", "target_position", "profile_velocity", "profile_acceleration", "profile_deceleration",
         "max_profile_velocity", "max_current")  # fmt: skip
Controlled = Callable[[], bool]
#: a condition of the axis's (position rad from the start, speed rad/s) that ends a wait
Done = Callable[[float, float], bool]


class BadExperiment(InvalidInput):
    """Options out of range, or a profile that does not fit the position window."""


class LimitExceeded(RefusedForSafety):
    """A safety limit was exceeded: the axis was quick-stopped and the run ended."""


class DriveFaulted(RefusedForSafety):
    """The drive went to fault during the run (a following error, a protection): the run ended, its cause said."""


class ControllerLost(RefusedForSafety):
    """The axis's controller went away while the experiment turned the motor: quick-stopped."""


@dataclass(frozen=True)
class ExperimentOptions:
    speed_rpm: float = 800.0
    acceleration_rpm_s: float = 5000.0
    hold_s: float = 0.2
    position_window_rev: float = 6.0
    current_limit_pct: float = 150.0
    cycles: float = 2.0

    def __post_init__(self) -> None:
        for name, (low, high) in RANGES.items():
            value = getattr(self, name)
            if not low <= value <= high:
                raise BadExperiment(f"{name} {value:g}: use {low:g}..{high:g}")

    def as_dict(self) -> dict[str, float]:
        return asdict(self)


RANGES = {
    "speed_rpm": (50.0, 6000.0),
    "acceleration_rpm_s": (500.0, 200000.0),
    "hold_s": (0.05, 2.0),
    "position_window_rev": (0.5, 1000.0),
    "current_limit_pct": (10.0, 300.0),
    "cycles": (1.0, 5.0),
}


@dataclass(frozen=True)
class Move:
    """One profile-position move: to ``target_rad`` (from the start) at ``speed_rad_s`` (the profile velocity)."""

    speed_rad_s: float
    target_rad: float
    seconds: float  # of the ideal trapezoid


def amplitude_rad(speed: float, hold: float, acceleration: float) -> float:
    """The target either side of the start that makes a move between opposite targets cruise ``hold`` at ``speed``:
    2X = v²/a (the two ramps) + v·hold."""
    return (speed**2 / acceleration + speed * hold) / 2


def profile(options: ExperimentOptions) -> list[Move]:
    """The moves of the run, the last back to the start."""
    top = options.speed_rpm * TWO_PI / 60
    low = top * LOW_SHARE
    acceleration = _accel(options)
    high_x = amplitude_rad(top, options.hold_s, acceleration)
    low_x = amplitude_rad(low, options.hold_s * LOW_HOLDS, acceleration)
    targets = [(top, high_x), (top, -high_x), (low, low_x), (low, -low_x)] * round(options.cycles) + [(low, 0.0)]
    moves, here = [], 0.0
    for speed, target in targets:
        moves.append(Move(speed, target, _trapezoid_s(abs(target - here), speed, acceleration)))
        here = target
    return moves


def _trapezoid_s(distance: float, speed: float, acceleration: float) -> float:
    """How long the ideal move of ``distance`` takes (a triangle when it never reaches ``speed``)."""
    if distance * acceleration < speed**2:
        return 2 * (distance / acceleration) ** 0.5
    return distance / speed + speed / acceleration


def excursion_rad(options: ExperimentOptions) -> float:
    """The largest distance of a target from the start, with FOLLOWING_MARGIN for the position loop's lag."""
    return FOLLOWING_MARGIN * max(abs(move.target_rad) for move in profile(options))


def check_fits(options: ExperimentOptions) -> None:
    window = options.position_window_rev * TWO_PI
    needed = excursion_rad(options)
    if needed > window:
        raise BadExperiment(
            f"the profile moves {needed / TWO_PI:.2f} revolutions from its start, beyond the position window of "
            f"{options.position_window_rev:g}: lower speed_rpm or hold_s, raise acceleration_rpm_s, or widen the window"
        )


def run_experiment(drive: Drive, options: ExperimentOptions, report: Callable[[str, float], None],
                   cancellation: Cancellation, controlled: Controlled) -> tuple[Record, dict[str, object]]:  # fmt: skip
    """Run the profile and record it; the axis is left disabled with every changed object as it was."""
    check_fits(options)
    scale = scales(drive)
    saved = read_values(drive, [name for name in SAVED if drive.profile.has(name)])
    try:
        _prepare(drive, options, scale)
        captured = _recorded(drive, options, scale, report, cancellation, controlled)
    finally:
        disable(drive)
        restore(drive, saved)
    top = options.speed_rpm * TWO_PI / 60
    levels = [top, -top, top * LOW_SHARE, -top * LOW_SHARE]
    return _record(captured, scale, levels), {"samples": captured.samples, "source": captured.source}


def _prepare(drive: Drive, options: ExperimentOptions, scale: Scales) -> None:
    """Profile position holding where the axis is, the ramps, speed and current limits of the run; then enabled."""
    speed = options.speed_rpm * TWO_PI / 60
    acceleration = options.acceleration_rpm_s * TWO_PI / 60 / scale.rad_s2_per_acceleration_unit
    values = {
        "modes_of_operation": MODE_PP,
        "target_position": int(drive.read("position_actual").raw),
        "profile_velocity": round(speed / scale.rad_s_per_speed_unit),
        "profile_acceleration": round(acceleration),
        "profile_deceleration": round(acceleration),
        "max_profile_velocity": round(1.1 * speed / scale.rad_s_per_speed_unit),
        "max_current": round(options.current_limit_pct * 10),
    }
    writes = [(drive.variable(name), value) for name, value in values.items() if drive.profile.has(name)]
    drive.submit_write_all(writes).future.result()
    set_state(drive, State.OPERATION_ENABLED)


def _recorded(drive: Drive, options: ExperimentOptions, scale: Scales, report: Callable[[str, float], None],
              cancellation: Cancellation, controlled: Controlled) -> Capture:  # fmt: skip
    """The capture on its own thread; the profile starts once it records."""
    moves = profile(options)
    duration = CAPTURE_STRETCH * (sum(move.seconds for move in moves) + END_S) + CAPTURE_MARGIN_S
    definition = CaptureDefinition(channels=CHANNELS, period_us=PERIOD_US, duration_s=duration,
                                   timeout_s=3 * duration + 10.0, source="tpdo")  # fmt: skip
    armed, stop = threading.Event(), Cancellation()
    outcome: dict[str, Any] = {}
    identity = DriveIdentity(bus="", node=drive.node, device=drive.profile.device)

    def record() -> None:
        try:
            outcome["capture"] = capture(drive, identity, definition, _armed_by(armed), stop)
        except BaseException as error:  # noqa: BLE001 - handed to the experiment's thread
            outcome["error"] = error
        armed.set()

    # the capture acts for whoever runs the experiment (its NMT start is judged by the motion guard as theirs)
    context = contextvars.copy_context()
    thread = threading.Thread(target=context.run, args=(record,), name=f"identification {drive.node}", daemon=True)
    thread.start()
    armed.wait(definition.timeout_s)
    try:
        if "error" not in outcome:
            _move(drive, moves, options, scale, report, cancellation, controlled)
    except BaseException:
        drive.write("controlword", QUICK_STOP)  # whatever ended the profile, the axis stops first
        stop.cancel()
        raise
    finally:
        thread.join()
    if "error" in outcome:
        raise outcome["error"]
    return outcome["capture"]


def _armed_by(armed: threading.Event) -> Callable[[dict[str, object]], None]:
    def report(event: dict[str, object]) -> None:
        if event.get("stage") in ("armed", "recording"):
            armed.set()

    return report


def _move(drive: Drive, moves: list[Move], options: ExperimentOptions, scale: Scales, report: Callable[[str, float],
          None], cancellation: Cancellation, controlled: Controlled) -> None:  # fmt: skip
    """Each move in turn until the axis stands at its target, watching the limits meanwhile; then the standstill."""
    start = int(drive.read("position_actual").raw)
    watch = _Watch(drive, options, scale, start)
    for number, move in enumerate(moves):
        drive.write("profile_velocity", max(1, round(move.speed_rad_s / scale.rad_s_per_speed_unit)))
        drive.write("target_position", start + round(move.target_rad / scale.rad_per_unit))
        drive.write("controlword", NEW_SET_POINT)
        drive.write("controlword", ENABLED_AT_ONCE)
        rpm = move.speed_rad_s * 60 / TWO_PI
        report(f"to {move.target_rad / TWO_PI:+.2f} rev at {rpm:.0f} rpm", number / len(moves))
        timeout = MOVE_TIMEOUT_FACTOR * move.seconds + MOVE_TIMEOUT_S
        _wait(watch, cancellation, controlled, _standing_at(move.target_rad, scale), timeout)
    _wait(watch, cancellation, controlled, _never, END_S)


def _accel(options: ExperimentOptions) -> float:
    return options.acceleration_rpm_s * TWO_PI / 60


def _standing_at(target: float, scale: Scales) -> Done:
    """The axis stands at ``target`` (within ARRIVED of a revolution, below STANDSTILL_RAD_S)."""
    tolerance = max(ARRIVED * TWO_PI, 2 * scale.rad_per_unit)
    return lambda position, speed: abs(position - target) <= tolerance and abs(speed) < STANDSTILL_RAD_S


def _never(_position: float, _speed: float) -> bool:
    """A wait that only ends with its time (the standstill at the end)."""
    return False


def _wait(watch: _Watch, cancellation: Cancellation, controlled: Controlled, done: Done, seconds: float) -> None:
    """Watch the limits until ``done(position rad, speed rad/s)`` or ``seconds`` have passed."""
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        watch.check(cancellation, controlled)
        if done(watch.position_rad, watch.speed_rad_s):
            return
        time.sleep(WATCH_SECONDS)


class _Watch:
    """The safety limits of one run, checked against values read from the drive."""

    def __init__(self, drive: Drive, options: ExperimentOptions, scale: Scales, start: int) -> None:
        self.drive, self.start = drive, start
        self.window = options.position_window_rev * TWO_PI / scale.rad_per_unit
        self.speed = SPEED_MARGIN * options.speed_rpm * TWO_PI / 60 / scale.rad_s_per_speed_unit
        self.current = CURRENT_MARGIN * options.current_limit_pct * 10
        self.scale = scale
        self.position_rad = self.speed_rad_s = 0.0

    def check(self, cancellation: Cancellation, controlled: Controlled) -> None:
        """The limits now; keeps the position (rad from the start) and speed read."""
        if cancellation.requested:
            self._stop()
            cancellation.check("identification")
        if not controlled():
            self._stop()
            raise ControllerLost(f"node {self.drive.node}: the axis's controller went away: identification stopped")
        values = read_values(self.drive, ["position_actual", "velocity_actual", "current_actual", "statusword"])
        if int(_number(values.get("statusword"), 0)) & FAULT_BIT:
            raise DriveFaulted(f"node {self.drive.node}: the drive faulted during the identification: "
                               f"{fault_cause(self.drive)}")  # fmt: skip
        exceeded = self._exceeded(values)
        if exceeded is not None:
            self._stop()
            raise LimitExceeded(f"node {self.drive.node}: limit exceeded: {exceeded}; the axis was quick-stopped")
        self.position_rad = (_number(values.get("position_actual"), self.start) - self.start) * self.scale.rad_per_unit
        self.speed_rad_s = _number(values.get("velocity_actual"), 0) * self.scale.rad_s_per_speed_unit

    def _exceeded(self, values: dict[str, object]) -> str | None:
        away = abs(_number(values.get("position_actual"), self.start) - self.start)
        if away > self.window:
            return f"position {away * self.scale.rad_per_unit / TWO_PI:.2f} rev from the start, limit {self._rev:.2f}"
        speed = abs(_number(values.get("velocity_actual"), 0))
        if speed > self.speed:
            return f"speed {speed:g}, limit {self.speed:g} (drive speed units)"
        current = abs(_number(values.get("current_actual"), 0))
        if current > self.current:
            return f"current {current / 10:g} % of rated, limit {self.current / 10:g} %"
        return None

    @property
    def _rev(self) -> float:
        return self.window * self.scale.rad_per_unit / TWO_PI

    def _stop(self) -> None:
        self.drive.write("controlword", QUICK_STOP)


def _number(value: object, default: float) -> float:
    return float(value) if isinstance(value, (int, float)) else default


def _record(captured: Capture, scale: Scales, levels: list[float]) -> Record:
    position, speed, current = captured.columns
    return Record(
        position_rad=[float(value) * scale.rad_per_unit for value in position],
        speed_rad_s=[float(value) * scale.rad_s_per_speed_unit for value in speed],
        torque_nm=[float(value) * scale.nm_per_permille for value in current],
        levels_rad_s=levels,
    )
