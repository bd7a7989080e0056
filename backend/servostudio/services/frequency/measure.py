"""One frequency-response measurement on a drive (docs/frequency-response.md): the axis runs in profile velocity
at a base speed, the multi-sine is streamed by RPDO at every SYNC — into the torque offset for the plant, into the
target velocity for the closed loop —, the drive's recorder records what the drive used and how the shaft moved,
whole periods are averaged, and a watch stops the axis (quick stop) when it leaves its position window or exceeds
its current limit.

The run is the axis's armed controller (``services.procedures`` does the same): every SDO write goes through the
drive's gate, the motion guard; the RPDO frames only change a target of the axis the run enabled, and they stop
when the controller goes away.  Whatever happens, the stream is stopped, the RPDO written back, the axis slowed to
rest and disabled, and every object the measurement changed put back.
"""

from __future__ import annotations

import cmath
import logging
import math
import threading
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from servostudio.drive.access import Drive
from servostudio.drive.cia402 import State
from servostudio.drive.control import set_state
from servostudio.drive.link import BusLink
from servostudio.drive.sync import CYCLE_PERIOD
from servostudio.errors import InvalidInput, ServoStudioError
from servostudio.services.cancel import Cancellation, Cancelled
from servostudio.services.frequency import estimate, markers, timed, tpdo_source
from servostudio.services.frequency.excitation import Multisine, design
from servostudio.services.frequency.speed_loop import NoSpeedLoop, read_speed_loop
from servostudio.services.frequency.stream import ExcitationStream
from servostudio.services.frequency.tpdo_source import ResponsePlan, ResponseStream, plan_response
from servostudio.services.procedures.run import disable, read_values, restore
from servostudio.services.procedures.units import TWO_PI, units_per_revolution
from servostudio.services.scope import Capture, CaptureDefinition, CapturePlan, DriveIdentity, NoRecorder
from servostudio.services.scope.capture import build_capture
from servostudio.services.scope.recorder import RecorderSession, UploadFailed
from servostudio.services.scope.service import check, record_once, session_of
from servostudio.services.scope.stream import StreamFailed

log = logging.getLogger(__name__)
LOOPS = ("plant", "closed")
MODE_PV = 3
#: 3 control periods (1333 SYNC/s): the 1-ms current monitor then takes each excitation step at each of its 4
#: positions in turn; at one fixed position the current loop's settling after each step biased the measured phase
#: by up to ±20° at 200 Hz (measured on the simulator), averaged over the four by < 1°
SYNC_PERIOD_S = 750e-6
#: SYNCs after which the 0.75-ms SYNC and the 1-ms current monitor line up again (3 ms); the excitation keeps its
#: lines off the bins that pattern mixes them onto (excitation.design), so the sampled current's images of the
#: steps land where nothing is measured
MONITOR_PATTERN = 4
#: the recorder's sample period: the control period (0x6064 every period; 0x6078 changes every 1 ms)
RECORD_PERIOD_US = 250.0
#: records between two updates of the current actual value 0x6078 (docs/control-loops.md §6)
CURRENT_HOLD = 4
#: 0x6078 holds the current measured in the control period before the record's (the 1-ms monitor takes it before
#: the period's loop runs): its line is advanced by one control period
CURRENT_LATENCY_S = 250e-6
#: the plant is measured with the speed loop's proportional gain divided by this (and the integral by its square):
#: the loop then only holds the base speed (crossover ≈ 1/30 of the tuned one, below the lowest line), so the
#: torque excitation reaches the shaft instead of being cancelled by the loop (docs/frequency-response.md §3)
SOFTEN = 30.0
#: what the excitation drives, by loop and source: the torque offset (the recorder's plant) or the target velocity
EXCITED = {("plant", "recorder"): "torque_offset", ("plant", "tpdo"): "target_velocity",
           ("closed", "recorder"): "target_velocity", ("closed", "tpdo"): "target_velocity"}  # fmt: skip
#: line amplitudes ∝ f^tilt (excitation.py), by loop and source
TILT = {("plant", "recorder"): 0.0, ("plant", "tpdo"): -0.25, ("closed", "recorder"): 0.5, ("closed", "tpdo"): 0.5}
#: plant: % of the rated current; closed loop: % of the base speed
DEFAULT_AMPLITUDE_PCT = {"plant": 50.0, "closed": 40.0}
#: a velocity excitation of the plant swings the speed by at most this share of the base speed (never near zero)
MAX_SWING = 0.8
#: control periods per SYNC: the 1-ms current monitor (CURRENT_HOLD periods) against the 0.75-ms SYNC
SYNC_PERIODS = 3
#: the TPDO response may take this many times its ideal duration plus RESPONSE_MARGIN_S before the run gives up
RESPONSE_STRETCH, RESPONSE_MARGIN_S = 3.0, 10.0
#: a period of the TPDO response is dropped (and another one taken) when two of its SYNCs, or of the RELOCK_SYNCS
#: before it, left more than STALL_S apart: a drive locked to the SYNC lost it and takes some to lock again (the
#: simulator unlocks after 0.25 s of silence and locks again after 32 SYNCs; docs/frequency-response.md §8)
STALL_S, RELOCK_SYNCS = 0.1, 64
SETTLE_S = 0.4
#: what the watch checks
WATCHED = ("position_actual", "current_actual")
WATCH_S = 0.05
STOP_WAIT_S = 1.5
RECORDING_TIMEOUT_S = 10.0
UPLOAD_TRIES = 2
Report = Callable[[dict[str, object]], None]


class BadMeasurement(InvalidInput):
    """A measurement refused before anything was written."""


@dataclass(frozen=True)
class MeasureRequest:
    loop: str = "plant"
    from_hz: float = 5.0
    to_hz: float = 400.0
    points: int = 60
    #: plant: peak torque offset in % of the rated current; closed: peak speed excursion in % of the base speed
    amplitude_pct: float | None = None
    base_speed_rad_s: float = 10.0
    #: revolutions the axis may travel from where it starts
    position_window: float = 10.0
    current_limit_a: float | None = None
    periods: int = 4

    @property
    def amplitude(self) -> float:
        return self.amplitude_pct if self.amplitude_pct is not None else DEFAULT_AMPLITUDE_PCT[self.loop]


def source_of(drive: Drive) -> str:
    """Where the response comes from: the drive's recorder where its profile has one, else synchronous TPDOs."""
    return "recorder" if drive.profile.recorder is not None else "tpdo"


def check_request(drive: Drive, request: MeasureRequest, bitrate: int | None = None) -> Multisine:
    """Everything that refuses a measurement, before anything is written; the excitation it will send."""
    if request.loop not in LOOPS:
        raise BadMeasurement(f"loop {request.loop!r}: use plant or closed")
    source = source_of(drive)
    if not 0 < request.amplitude <= 100:
        raise BadMeasurement(f"amplitude {request.amplitude:g} %: give 0 < amplitude ≤ 100")
    limits = (request.base_speed_rad_s, request.position_window, request.current_limit_a or 1.0)
    if not all(math.isfinite(value) and value > 0 for value in limits):
        raise BadMeasurement("base speed, position window and current limit must be > 0")
    if not 2 <= request.periods <= 32:
        raise BadMeasurement(f"{request.periods} periods: give 2 … 32")
    if source == "tpdo":
        _response_plan(drive, request, bitrate)
    tilt = TILT[(request.loop, source)]
    return design(request.from_hz, request.to_hz, request.points, SYNC_PERIOD_S, tilt, MONITOR_PATTERN)


def _follows_sync(drive: Drive) -> bool:
    """A drive that can be told the SYNC period (0x1006) locks its control cycle to the SYNC (CiA 301); one that
    cannot free-runs, and its response is placed in time (``timed``)."""
    return drive.dictionary is not None and drive.dictionary.get(*CYCLE_PERIOD) is not None


def _control_period_s(drive: Drive) -> float:
    """The drive's control period (its speed-loop description's), the grid its answers' values come from."""
    loop = drive.profile.speed_loop
    return loop.control_period_s if loop is not None else RECORD_PERIOD_US * 1e-6


def _response_plan(drive: Drive, request: MeasureRequest, bitrate: int | None) -> ResponsePlan:
    """The TPDO response's plan, or the refusal: a plant needs the current actual value, and the bus the SYNC
    rate's frames."""
    current = _present(drive, "current_actual")
    if request.loop == "plant" and not current:
        raise NoRecorder(
            f"node {drive.node}: the {drive.profile.device} has no recorder and names no current actual value "
            "(0x6078): the plant cannot be measured through TPDOs; measure the closed loop"
        )
    excited = drive.variable(EXCITED[(request.loop, "tpdo")])
    return plan_response(drive, excited, bitrate, SYNC_PERIOD_S, current)


@dataclass
class Limits:
    """What the watch checks, in the drive's raw units."""

    start: int
    window_units: float
    current_permille: float | None


class Watch:
    """Reads position and current every ``WATCH_S`` while the axis runs; the first limit exceeded (or the controller
    gone, or a cancel) stops the axis once, by ``stop``, and is kept as ``reason``."""

    def __init__(
        self,
        drive: Drive,
        limits: Limits,
        stop: Callable[[str], None],
        controlled: Callable[[], bool],
        cancellation: Cancellation,
        read: Callable[[], Mapping[str, object]] | None = None,
    ) -> None:
        self.drive, self.limits, self._stop, self.controlled, self.cancellation = (
            drive,
            limits,
            stop,
            controlled,
            cancellation,
        )
        #: position and current now (by SDO unless the measurement's TPDOs bring them)
        self.read = read or (lambda: read_values(drive, list(WATCHED)))
        self.reason: str | None = None
        self.halt = Cancellation()  # the recording in progress ends with the watch
        self._done = threading.Event()
        self._thread = threading.Thread(target=self._run, name=f"bode watch {drive.node}", daemon=True)

    def start(self) -> Watch:
        self._thread.start()
        return self

    def close(self) -> None:
        self._done.set()
        self._thread.join(5.0)

    def _run(self) -> None:
        while not self._done.wait(WATCH_S):
            try:
                reason = self._exceeded()
            except ServoStudioError as error:
                reason = f"the drive could not be watched: {error}"
            if reason is not None:
                self._trip(reason)
                return

    def _exceeded(self) -> str | None:
        if self.cancellation.requested:
            return "cancelled by its client"
        if not self.controlled():
            return "the axis's controller went away"
        values = self.read()
        limits = self.limits
        travel = abs(int(str(values.get("position_actual", limits.start))) - limits.start)
        if travel > limits.window_units:
            return f"position window exceeded: travel {travel:.0f} > {limits.window_units:.0f} user units"
        current = abs(int(str(values.get("current_actual", 0))))
        if limits.current_permille is not None and current > limits.current_permille:
            return f"current limit exceeded: {current} ‰ > {limits.current_permille:.0f} ‰ of the rated current"
        return None

    def _trip(self, reason: str) -> None:
        self.reason = reason
        self.halt.cancel()
        try:
            self._stop(reason)
        except ServoStudioError as error:
            self.reason = f"{reason}; the quick stop failed: {error}"


@dataclass
class Axis:
    """What the measurement knows of the drive: units, the current the ‰ of 0x6078 refer to, torque constant."""

    units_per_rev: float
    rated_a: float
    torque_constant: float | None
    rad_s_per_speed_unit: float

    @classmethod
    def of(cls, drive: Drive) -> Axis:
        reference = drive.profile.current_reference
        rated = float(drive.read(reference).physical) if _present(drive, reference) else 1.0
        name = drive.profile.procedures.torque_constant
        kt = float(drive.read(name).physical) if name is not None and _present(drive, name) else None
        if not kt and reference == "rated_current" and rated > 0 and _present(drive, "rated_torque"):
            kt = float(drive.read("rated_torque").raw) / 1000.0 / rated  # 0x6076 mN·m of the rated current
        units = units_per_revolution(drive)
        return cls(units, rated, kt or None, drive.profile.speed_unit_rad_s or TWO_PI / units)

    def rad(self, user: float) -> float:
        return user / self.units_per_rev * TWO_PI

    def user(self, rad: float) -> float:
        return rad / TWO_PI * self.units_per_rev

    def speed_rad(self, speed: float) -> float:
        """rad/s of a speed in the drive's speed unit (0x606C, 0x60FF)."""
        return speed * self.rad_s_per_speed_unit

    def speed_user(self, rad_s: float) -> float:
        return rad_s / self.rad_s_per_speed_unit


def _present(drive: Drive, name: str) -> bool:
    """The profile names the object and the drive's dictionary has it."""
    if not drive.profile.has(name) or drive.dictionary is None:
        return False
    return drive.dictionary.get(*drive.profile.address(name)) is not None


@dataclass
class Collected:
    """What a source collected: whole periods, and the estimate from them (computed only for a completed run)."""

    source: str
    periods: int = 0
    points: Callable[[], list[estimate.Point]] = list
    #: the plant is per N·m (the drive gives its torque constant), not per ampere: its J and B can be fitted
    in_torque: bool = True


def measure(
    drive: Drive,
    link: BusLink,
    request: MeasureRequest,
    report: Report,
    cancellation: Cancellation,
    controlled: Callable[[], bool],
    quick_stop: Callable[[str], None],
    operational: bool,
    bitrate: int | None = None,
) -> dict[str, Any]:
    """The measurement, start to end: the result dict without its identity fields (the service adds those)."""
    signal = check_request(drive, request, bitrate)
    source, axis, gains = source_of(drive), Axis.of(drive), _gains(drive)
    saved = read_values(drive, _touched(drive, request, source))
    stream = ExcitationStream(drive, link, drive.variable(EXCITED[(request.loop, source)]), SYNC_PERIOD_S)
    response = ResponseStream(_response_plan(drive, request, bitrate), drive, link) if source == "tpdo" else None
    start = int(drive.read("position_actual").raw)
    limits = Limits(start, request.position_window * axis.units_per_rev, _current_permille(request, axis))
    watch: Watch | None = None
    collected = Collected(source)
    try:
        _prepare(drive, request, saved, axis, source)
        values = _values(request, signal, axis, source, gains, _waveform(drive, signal, response))
        watch = Watch(drive, limits, quick_stop, controlled, cancellation, _watched(drive, response)).start()
        stream.open(operational)
        if response is not None:
            response.open()
        stream.start(values, response.answered if response is not None else None)
        report({"stage": "settling", "fraction": 0.05})
        collected = _collect(drive, request, signal, axis, watch, report, stream, response, values)
    finally:
        left = _put_back(drive, stream, watch, saved, response)
    if cancellation.requested and (watch is None or watch.reason == "cancelled by its client"):
        raise Cancelled("frequency response cancelled by its client")
    return _result(request, signal, collected, gains, watch.reason if watch else None, left)


def _watched(drive: Drive, response: ResponseStream | None) -> Callable[[], Mapping[str, object]]:
    """The watch's reading: the TPDO response's last sample once it runs (no SDO between the SYNCs), else SDO."""

    def read() -> Mapping[str, object]:
        latest = response.latest() if response is not None else None
        return latest if latest is not None else read_values(drive, list(WATCHED))

    return read


def _collect(drive: Drive, request: MeasureRequest, signal: Multisine, axis: Axis, watch: Watch, report: Report,
             stream: ExcitationStream, response: ResponseStream | None,
             sent: Callable[[int], int]) -> Collected:  # fmt: skip
    """Settle, then whole periods from the recorder or the TPDO response, until ``request.periods`` are there or the
    watch stopped the axis."""
    in_torque = axis.torque_constant is not None
    if response is None:
        _pause(watch, SETTLE_S + signal.period_s)
        captures = _record(drive, request, signal, watch, report, stream)
        periods = sum(len(c.columns[0]) // _block(signal) for c in captures)
        return Collected("recorder", periods, lambda: _estimate(request, signal, axis, captures), in_torque)
    if not _follows_sync(drive):
        period_s = _control_period_s(drive)
        answers = _follow_in_time(response, stream, signal, watch, report, period_s)
        windows = timed.WINDOWS if answers is not None else 0
        return Collected("tpdo", windows, lambda: _timed_estimate(request, signal, axis, answers, period_s),
                         in_torque)  # fmt: skip
    blocks = _follow(response, stream, signal, request, watch, report)
    return Collected("tpdo", len(blocks), lambda: _tpdo_estimate(request, signal, axis, blocks, sent), in_torque)


#: the answers of a free-running drive: the drive's control periods they were taken in, their columns, and the
#: starts of the windows the estimate takes
Answers = tuple[list[int], list[list[float]], list[float]]


def _follow_in_time(response: ResponseStream, stream: ExcitationStream, signal: Multisine, watch: Watch,
                    report: Report, period_s: float) -> Answers | None:  # fmt: skip
    """A free-running drive's answers after settling, until they hold ``timed.WINDOWS`` windows without a stall
    (counted in the drive's time) or ``timed.MORE_WINDOWS`` times the answers those take came; None when the watch
    stopped the axis."""
    start = math.ceil((SETTLE_S + signal.period_s) / SYNC_PERIOD_S)
    count = math.ceil((timed.WINDOWS + 1) * signal.period_s / SYNC_PERIOD_S)
    deadline = time.monotonic() + RESPONSE_STRETCH * (start + count) * SYNC_PERIOD_S + RESPONSE_MARGIN_S
    most = round(timed.MORE_WINDOWS * count)
    while True:
        if not _answered(response, stream, start + count, watch, deadline):
            return None
        periods = timed.ticks(response.sync_instants(start, count), period_s)
        instants = [n * period_s for n in periods]
        starts = timed.clean_windows(instants, signal.period_s, timed.WINDOWS, count >= most)
        if starts is not None:
            report({"stage": "recording", "fraction": 0.9})
            return periods, response.columns(start, count), starts
        count += math.ceil(signal.period_s / SYNC_PERIOD_S)


#: one period of the TPDO response: its first sample's number and the columns of its samples plus the next one
Block = tuple[int, list[list[float]]]


def _follow(response: ResponseStream, stream: ExcitationStream, signal: Multisine, request: MeasureRequest,
            watch: Watch, report: Report) -> list[Block]:  # fmt: skip
    """``request.periods`` whole periods of the response after settling, each one whose SYNCs stalled replaced by
    the next; fewer when the watch stopped the axis."""
    size = signal.samples
    start = math.ceil((SETTLE_S + signal.period_s) / SYNC_PERIOD_S / size) * size
    ideal = (start + request.periods * size) * SYNC_PERIOD_S
    deadline = time.monotonic() + RESPONSE_STRETCH * ideal + RESPONSE_MARGIN_S
    kept: list[int] = []
    while len(kept) < request.periods and _answered(response, stream, start + size + 1, watch, deadline):
        if stream.stalled(start - RELOCK_SYNCS, start + size, STALL_S) or response.stalled(
            start - RELOCK_SYNCS, start + size, STALL_S
        ):
            log.info("node %s: frequency response: SYNCs stalled in period %d, taking another", response.plan.node,
                     start // size)  # fmt: skip
        else:
            kept.append(start)
            report({"stage": "recording", "fraction": round(0.1 + 0.8 * len(kept) / request.periods, 3)})
        start += size
    return [(first, response.columns(first, size + 1)) for first in kept]


def _answered(response: ResponseStream, stream: ExcitationStream, count: int, watch: Watch, deadline: float) -> bool:
    """Wait until the TPDOs answered ``count`` SYNCs (True) or the watch stopped the axis (False); a stopped SYNC
    or a response that does not come by ``deadline`` fails the run."""
    while response.answered() < count:
        if watch.halt.requested:
            return False
        if stream.error is not None:
            raise StreamFailed(f"node {response.plan.node}: the measurement's SYNC stopped: {stream.error}")
        if time.monotonic() > deadline:
            raise StreamFailed(f"node {response.plan.node}: the drive answered {response.answered()} of the "
                               f"{count} SYNCs the response needs in time")  # fmt: skip
        time.sleep(WATCH_S / 5)
    return not watch.halt.requested


def _put_back(drive: Drive, stream: ExcitationStream, watch: Watch | None, saved: Mapping[str, object],
              response: ResponseStream | None) -> str | None:  # fmt: skip
    """Stream, TPDOs, RPDO, node, axis and objects as they were — each step tried whatever the others did; what
    failed, or None (a failure during an error is logged, so it does not hide the error)."""
    if watch is not None:
        watch.close()
    stream.stop()  # no SYNC while the response's TPDOs are written back
    left = [response.close() if response is not None else None, stream.close()]
    failures = [failure for failure in left if failure is not None]
    for what, step in (
        ("the axis was not stopped", lambda: _stop(drive, saved)),
        ("the objects were not put back", lambda: restore(drive, saved)),
    ):
        try:
            step()
        except ServoStudioError as error:
            failures.append(f"{what}: {error}")
    if failures:
        log.warning("node %s: frequency response: %s", drive.node, "; ".join(failures))
    return "; ".join(failures) or None


def _torque_excited(request: MeasureRequest, source: str) -> bool:
    return EXCITED[(request.loop, source)] == "torque_offset"


def _touched(drive: Drive, request: MeasureRequest, source: str) -> list[str]:
    names = [
        "modes_of_operation",
        "target_velocity",
        "torque_offset",
        "profile_acceleration",
        "profile_deceleration",
        "max_profile_velocity",
    ]
    if request.loop == "plant":
        names.append("current_monitor_filter")
    if _torque_excited(request, source):
        names += _soft_gain_names(drive)
    return [name for name in names if _present(drive, name)]


def _soft_gain_names(drive: Drive) -> list[str]:
    loop = drive.profile.speed_loop
    if loop is None:
        return []
    return [loop.gains[key].object for key in ("kp_a_per_rad_s", "ki_a_per_rad") if key in loop.gains]


def _gains(drive: Drive) -> dict[str, Any] | None:
    try:
        gains = read_speed_loop(drive)
    except NoSpeedLoop:
        return None
    gains.pop("raw", None)
    return gains


def _current_permille(request: MeasureRequest, axis: Axis) -> float | None:
    if request.current_limit_a is None:
        return None
    return 1000.0 * request.current_limit_a / axis.rated_a


def _prepare(drive: Drive, request: MeasureRequest, saved: Mapping[str, object], axis: Axis, source: str) -> None:
    """Profile velocity with ramps the loop never sees, the loop softened under a torque excitation, enabled at the
    base speed."""
    writes: list[tuple[str, int]] = [("modes_of_operation", MODE_PV), ("torque_offset", 0), ("target_velocity", 0)]
    steep = _high(drive, "profile_acceleration")
    writes += [("profile_acceleration", steep), ("profile_deceleration", steep)]
    base = round(axis.speed_user(request.base_speed_rad_s))
    top = axis.speed_user(request.base_speed_rad_s * 3.0)  # the base speed, and any swing (≤ base speed) twice over
    if _present(drive, "max_profile_velocity") and float(str(saved.get("max_profile_velocity", 0))) < top:
        writes.append(("max_profile_velocity", round(top)))
    if _torque_excited(request, source):
        writes += _soft_writes(drive, saved)
    if request.loop == "plant" and _present(drive, "current_monitor_filter"):
        writes.append(("current_monitor_filter", _high(drive, "current_monitor_filter")))
    present = [(drive.variable(name), value) for name, value in writes if _present(drive, name)]
    drive.submit_write_all(present).future.result()
    set_state(drive, State.OPERATION_ENABLED)
    drive.write("target_velocity", base)


def _soft_writes(drive: Drive, saved: Mapping[str, object]) -> list[tuple[str, int]]:
    names = _soft_gain_names(drive)
    divisors = (SOFTEN, SOFTEN * SOFTEN)
    return [
        (name, round(int(str(saved.get(name, 0))) / divisor)) for name, divisor in zip(names, divisors, strict=False)
    ]


def _high(drive: Drive, name: str) -> int:
    """The largest value the object takes (its high limit, else its type's)."""
    variable = drive.variable(name)
    if variable.high is not None:
        return int(variable.high)
    bits = variable.data_type.fixed_size * 8
    return (1 << (bits - 1 if variable.data_type.is_signed else bits)) - 1


def _values(request: MeasureRequest, signal: Multisine, axis: Axis, source: str, gains: Mapping[str, Any] | None,
            waveform: Callable[[int], float]) -> Callable[[int], int]:  # fmt: skip
    """Value k of the stream in the excited object's raw unit, of ``waveform(k)`` (peak 1)."""
    if _torque_excited(request, source):
        peak = 10.0 * request.amplitude  # ‰ of the rated current
        return lambda k: round(peak * waveform(k))
    base = axis.speed_user(request.base_speed_rad_s)
    swing = axis.speed_user(_swing(request, axis, gains))
    return lambda k: round(base + swing * waveform(k))


def _waveform(drive: Drive, signal: Multisine, response: ResponseStream | None) -> Callable[[int], float]:
    """The multi-sine's sample k for SYNC k; for a free-running drive its value at the drive's present instant (its
    answers' clock), so the excitation is periodic in the drive's time, not in the SYNCs' count (``timed``)."""
    if response is None or _follows_sync(drive):
        return signal.value
    return timed.in_time(timed.Excitation(signal), response.clock.now, SYNC_PERIOD_S)


def _swing(request: MeasureRequest, axis: Axis, gains: Mapping[str, Any] | None) -> float:
    """The velocity excitation's peak, rad/s: for the closed loop ``amplitude`` % of the base speed; for the plant the
    swing whose loop error asks ``amplitude`` % of the rated current of the proportional gain (above the loop's
    bandwidth the current is KPv × the swing: a stiff loop on a heavy axis saturates its current at a swing a
    light one hardly feels), at most ``MAX_SWING`` of the base speed; without a known KPv, that share of it."""
    base = request.base_speed_rad_s
    if request.loop == "closed":
        return base * request.amplitude / 100.0
    kp = float((gains or {}).get("kp_a_per_rad_s") or 0.0)
    current = request.amplitude / 100.0 * axis.rated_a
    return min(current / kp, MAX_SWING * base) if kp > 0 else MAX_SWING * base * request.amplitude / 100.0


def _pause(watch: Watch, seconds: float) -> bool:
    """Wait ``seconds`` unless the watch stops the axis first; True when it did."""
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline and not watch.halt.requested:
        time.sleep(0.01)
    return watch.halt.requested


def _channels(request: MeasureRequest) -> tuple[str, ...]:
    if request.loop == "plant":
        return ("position_actual", "current_actual", "torque_offset")
    return ("target_velocity", "position_actual")


def _record(drive: Drive, request: MeasureRequest, signal: Multisine, watch: Watch, report: Report,
            stream: ExcitationStream) -> list[Capture]:  # fmt: skip
    """Recordings of whole periods until ``request.periods`` are there (or the watch stops the axis); a recording
    during which the SYNCs stalled is taken again, as a TPDO period is (``_follow``), up to ``request.periods``
    times: a drive locked to the SYNC loses it, and its excitation is no longer periodic."""
    block = _block(signal)
    definition = CaptureDefinition(
        channels=_channels(request), period_us=RECORD_PERIOD_US, samples=2, timeout_s=RECORDING_TIMEOUT_S
    )
    capacity = _capacity(drive, definition)
    per_recording = max(1, min(request.periods, (capacity - 1) // block))
    session = session_of(drive)
    identity = DriveIdentity(bus="", node=drive.node, device=drive.profile.device)
    captures: list[Capture] = []
    retakes = request.periods
    while sum(len(c.columns[0]) // block for c in captures) < request.periods and watch.reason is None:
        plan = check(
            drive,
            CaptureDefinition(
                channels=definition.channels,
                period_us=RECORD_PERIOD_US,
                samples=per_recording * block + 1,
                timeout_s=RECORDING_TIMEOUT_S,
            ),
        )
        assert isinstance(plan, CapturePlan)
        session.configure(plan)
        first = stream.sent
        try:
            capture = _recording(session, plan, identity, watch.halt)
        except Cancelled:
            break
        if retakes > 0 and stream.stalled(first - RELOCK_SYNCS, stream.sent, STALL_S):
            log.info("node %s: frequency response: SYNCs stalled during a recording, taking another", drive.node)
            retakes -= 1
            continue
        captures.append(capture)
        done = sum(len(c.columns[0]) // block for c in captures)
        report({"stage": "recording", "fraction": round(0.1 + 0.8 * min(done / request.periods, 1.0), 3)})
    return captures


def _recording(session: RecorderSession, plan: CapturePlan, identity: DriveIdentity, halt: Cancellation) -> Capture:
    """One recording; its upload tried again up to twice (the stream keeps the bus busy, a block upload can time
    out; the recording stays in the drive)."""
    try:
        return record_once(session, plan, identity, _quiet, halt)
    except UploadFailed:
        for attempt in range(UPLOAD_TRIES):
            try:
                recording = session.upload(plan, _quiet, halt)
            except UploadFailed:
                if attempt == UPLOAD_TRIES - 1:
                    raise
                continue
            return build_capture(plan, recording.data, recording.trigger_record, identity)
        raise


def _quiet(event: dict[str, object]) -> None:
    """The recorder's own stages are not reported (the measurement reports its periods)."""


def _block(signal: Multisine) -> int:
    return round(signal.period_s / (RECORD_PERIOD_US * 1e-6))


def _capacity(drive: Drive, definition: CaptureDefinition) -> int:
    """The most records the recorder holds with these channels."""
    capacity = int(session_of(drive).limits().capacity)
    return capacity // sum(drive.variable(name).data_type.fixed_size for name in definition.channels)


def _stop(drive: Drive, saved: Mapping[str, object]) -> None:
    """Slow to rest with the user's ramps, then disable."""
    try:
        ramps = [
            (drive.variable(name), saved[name])
            for name in ("profile_acceleration", "profile_deceleration")
            if name in saved
        ]
        writes = [*ramps, (drive.variable("target_velocity"), 0)]
        drive.submit_write_all(writes).future.result()
        deadline = time.monotonic() + STOP_WAIT_S
        while time.monotonic() < deadline and abs(int(drive.read("velocity_actual").raw)) > 0:
            time.sleep(0.02)
    finally:
        disable(drive)


def _result(
    request: MeasureRequest,
    signal: Multisine,
    collected: Collected,
    gains: dict[str, Any] | None,
    aborted: str | None,
    left: str | None,
) -> dict[str, Any]:
    """The result dict (contract of issue #16); an aborted measurement has no points."""
    if left is not None:
        aborted = f"{aborted}; {left}" if aborted else left
    points: list[estimate.Point] = [] if aborted else collected.points()
    source = collected.source
    shown = estimate.as_points(points)
    return {
        "kind": "frequency_response",
        "loop": request.loop,
        "excitation": {
            "type": "multisine",
            "from_hz": request.from_hz,
            "to_hz": request.to_hz,
            "points": len(signal.harmonics),
            "amplitude_pct": request.amplitude,
            "base_speed_rad_s": request.base_speed_rad_s,
            "periods": collected.periods,
            "sample_period_us": RECORD_PERIOD_US if source == "recorder" else round(SYNC_PERIOD_S * 1e6, 3),
            "source": source,
            # what the magnitude is per: the plant's torque (N·m), or its current (A) on a drive without a torque
            # constant (the CD1-k); the closed loop's demanded velocity
            "input": "velocity" if request.loop == "closed" else "torque" if collected.in_torque else "current",
        },
        "points": shown,
        "markers": markers.markers_of(request.loop, shown),
        "plant_fit": estimate.rigid_fit(points) if request.loop == "plant" and points and collected.in_torque else None,
        "gains": gains,
        "aborted": aborted,
    }


def _estimate(request: MeasureRequest, signal: Multisine, axis: Axis, captures: list[Capture]) -> list[estimate.Point]:
    """Plant: shaft speed over the recorded current, through the torque offset the drive applied (the reference);
    closed loop: shaft speed over the recorded target velocity (H1)."""
    block, harmonics, frequencies = _block(signal), signal.harmonics, signal.frequencies_hz
    reference: list[estimate.Lines] = []
    inputs: list[estimate.Lines] = []
    outputs: list[estimate.Lines] = []
    for capture in captures:
        columns = [list(map(float, column)) for column in capture.columns]
        if request.loop == "plant":
            positions = [axis.rad(value) for value in columns[0]]
            torque = (axis.torque_constant or 1.0) * axis.rated_a / 1000.0
            current = [torque * value for value in columns[1]]
            lines = estimate.held_lines(current, harmonics, block, CURRENT_HOLD)
            inputs += [_advanced(row, frequencies, CURRENT_LATENCY_S) for row in lines]
            reference += estimate.block_lines(columns[2], harmonics, block)
        else:
            positions = [axis.rad(value) for value in columns[1]]
            inputs += estimate.block_lines([axis.speed_rad(value) for value in columns[0]], harmonics, block)
        outputs += estimate.speed_lines(estimate.position_lines(positions, harmonics, block), frequencies)
    if request.loop == "plant":
        return estimate.by_reference(reference, inputs, outputs, frequencies)
    return estimate.h1(inputs, outputs, frequencies)


def _advanced(row: estimate.Lines, frequencies: list[float], seconds: float) -> estimate.Lines:
    return [value * cmath.exp(2j * math.pi * f * seconds) for value, f in zip(row, frequencies, strict=True)]


def _tpdo_estimate(request: MeasureRequest, signal: Multisine, axis: Axis, blocks: list[Block],
                   sent: Callable[[int], int]) -> list[estimate.Point]:  # fmt: skip
    """From the TPDO response (position, target velocity read back, current): the closed loop from the staircase
    of targets the drive held (its latency found from the read-back) to the shaft speed (H1); the plant from the
    current, each value at the instant it was measured, to the shaft speed, through the targets (the reference)."""
    size, harmonics, frequencies = signal.samples, list(signal.harmonics), signal.frequencies_hz
    torque = (axis.torque_constant or 1.0) * axis.rated_a / 1000.0
    targets, currents, outputs = [], [], []
    for first, columns in blocks:
        positions = [axis.rad(value) for value in columns[0]]
        outputs += estimate.speed_lines(estimate.position_lines(positions, harmonics, size), frequencies)
        lines = estimate.block_lines([axis.speed_rad(value) for value in columns[1]], harmonics, size)
        delay = tpdo_source.latency(columns[1][:size], sent, first)  # also: were the values applied at their SYNCs?
        if request.loop == "closed":
            targets += tpdo_source.held_input(lines, harmonics, size, delay)
        else:
            targets += lines
            currents += estimate.monitored_lines([torque * value for value in columns[2]], harmonics, size,
                                                 SYNC_PERIODS, CURRENT_HOLD)  # fmt: skip
    if request.loop == "closed":
        return estimate.h1(targets, outputs, frequencies)
    return estimate.by_reference(targets, currents, outputs, frequencies)


def _timed_estimate(request: MeasureRequest, signal: Multisine, axis: Axis, answers: Answers | None,
                    period_s: float) -> list[estimate.Point]:  # fmt: skip
    """A free-running drive's response placed in time (``timed``): each answer at the control period it was taken
    in, the current on its 1-ms monitor's own grid."""
    assert answers is not None
    periods, columns, starts = answers
    current = None
    if request.loop == "plant":
        torque = (axis.torque_constant or 1.0) * axis.rated_a / 1000.0
        current = timed.monitored(periods, [torque * value for value in columns[2]], CURRENT_HOLD, period_s,
                                  CURRENT_LATENCY_S)  # fmt: skip
    response = timed.Timed([n * period_s for n in periods], [axis.rad(value) for value in columns[0]],
                           [axis.speed_rad(value) for value in columns[1]], current)  # fmt: skip
    return timed.estimate_timed(request.loop, response, signal, starts)
