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
from servostudio.errors import InvalidInput, ServoStudioError
from servostudio.services.cancel import Cancellation, Cancelled
from servostudio.services.frequency import estimate, markers
from servostudio.services.frequency.excitation import Multisine, design
from servostudio.services.frequency.speed_loop import NoSpeedLoop, read_speed_loop
from servostudio.services.frequency.stream import ExcitationStream
from servostudio.services.procedures.run import disable, read_values, restore
from servostudio.services.procedures.units import TWO_PI, units_per_revolution
from servostudio.services.scope import Capture, CaptureDefinition, CapturePlan, DriveIdentity, NoRecorder
from servostudio.services.scope.capture import build_capture
from servostudio.services.scope.recorder import RecorderSession, UploadFailed
from servostudio.services.scope.service import check, record_once, session_of

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
#: line amplitudes ∝ f^tilt (excitation.py)
TILT = {"plant": 0.0, "closed": 0.5}
DEFAULT_AMPLITUDE_PCT = {"plant": 50.0, "closed": 40.0}
SETTLE_S = 0.4
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


def check_request(drive: Drive, request: MeasureRequest) -> Multisine:
    """Everything that refuses a measurement, before anything is written; the excitation it will send."""
    if request.loop not in LOOPS:
        raise BadMeasurement(f"loop {request.loop!r}: use plant or closed")
    if not 0 < request.amplitude <= 100:
        raise BadMeasurement(f"amplitude {request.amplitude:g} %: give 0 < amplitude ≤ 100")
    limits = (request.base_speed_rad_s, request.position_window, request.current_limit_a or 1.0)
    if not all(math.isfinite(value) and value > 0 for value in limits):
        raise BadMeasurement("base speed, position window and current limit must be > 0")
    if not 2 <= request.periods <= 32:
        raise BadMeasurement(f"{request.periods} periods: give 2 … 32")
    if drive.profile.recorder is None:
        raise NoRecorder(
            f"node {drive.node}: the {drive.profile.device} has no recorder: the frequency response "
            "records with the drive's recorder (synchronous TPDOs are not built yet)"
        )
    return design(request.from_hz, request.to_hz, request.points, SYNC_PERIOD_S, TILT[request.loop], MONITOR_PATTERN)


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
    ) -> None:
        self.drive, self.limits, self._stop, self.controlled, self.cancellation = (
            drive,
            limits,
            stop,
            controlled,
            cancellation,
        )
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
        values = read_values(self.drive, ["position_actual", "current_actual"])
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
    """What the measurement knows of the drive: units, rated current, torque constant."""

    units_per_rev: float
    rated_a: float
    torque_constant: float | None

    @classmethod
    def of(cls, drive: Drive) -> Axis:
        rated = float(drive.read("rated_current").physical) if drive.profile.has("rated_current") else 1.0
        name = drive.profile.procedures.torque_constant
        kt = float(drive.read(name).physical) if name is not None and drive.profile.has(name) else None
        return cls(units_per_revolution(drive), rated, kt or None)

    def rad(self, user: float) -> float:
        return user / self.units_per_rev * TWO_PI

    def user(self, rad: float) -> float:
        return rad / TWO_PI * self.units_per_rev


def measure(
    drive: Drive,
    link: BusLink,
    request: MeasureRequest,
    report: Report,
    cancellation: Cancellation,
    controlled: Callable[[], bool],
    quick_stop: Callable[[str], None],
    operational: bool,
) -> dict[str, Any]:
    """The measurement, start to end: the result dict without its identity fields (the service adds those)."""
    signal = check_request(drive, request)
    axis = Axis.of(drive)
    gains = _gains(drive)
    saved = read_values(drive, _touched(drive, request))
    stream = ExcitationStream(drive, link, drive.variable(_excited(request)), SYNC_PERIOD_S)
    start = int(drive.read("position_actual").raw)
    limits = Limits(start, request.position_window * axis.units_per_rev, _current_permille(request, axis))
    watch: Watch | None = None
    captures: list[Capture] = []
    try:
        _prepare(drive, request, saved, axis)
        watch = Watch(drive, limits, quick_stop, controlled, cancellation).start()
        stream.open(operational)
        stream.start(_values(request, signal, axis))
        report({"stage": "settling", "fraction": 0.05})
        _pause(watch, SETTLE_S + signal.period_s)
        captures = _record(drive, request, signal, watch, report)
    finally:
        left = _put_back(drive, stream, watch, saved)
    if cancellation.requested and (watch is None or watch.reason == "cancelled by its client"):
        raise Cancelled("frequency response cancelled by its client")
    return _result(request, signal, axis, captures, gains, watch.reason if watch else None, left)


def _put_back(drive: Drive, stream: ExcitationStream, watch: Watch | None, saved: Mapping[str, object]) -> str | None:
    """Stream, RPDO, node, axis and objects as they were — each step tried whatever the others did; what failed, or
    None (a failure during an error is logged, so it does not hide the error)."""
    failures: list[str] = []
    if watch is not None:
        watch.close()
    left = stream.close()
    if left is not None:
        failures.append(left)
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


def _excited(request: MeasureRequest) -> str:
    return "torque_offset" if request.loop == "plant" else "target_velocity"


def _touched(drive: Drive, request: MeasureRequest) -> list[str]:
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
        names += _soft_gain_names(drive)
    return [name for name in names if drive.profile.has(name)]


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


def _prepare(drive: Drive, request: MeasureRequest, saved: Mapping[str, object], axis: Axis) -> None:
    """Profile velocity with ramps the loop never sees, the plant's loop softened, enabled at the base speed."""
    writes: list[tuple[str, int]] = [("modes_of_operation", MODE_PV), ("torque_offset", 0), ("target_velocity", 0)]
    steep = _high(drive, "profile_acceleration")
    writes += [("profile_acceleration", steep), ("profile_deceleration", steep)]
    base = round(axis.user(request.base_speed_rad_s))
    top = axis.user(request.base_speed_rad_s * (2.0 + request.amplitude / 100.0))
    if drive.profile.has("max_profile_velocity") and float(str(saved.get("max_profile_velocity", 0))) < top:
        writes.append(("max_profile_velocity", round(top)))
    if request.loop == "plant":
        writes += _soft_writes(drive, saved)
        if drive.profile.has("current_monitor_filter"):
            writes.append(("current_monitor_filter", _high(drive, "current_monitor_filter")))
    present = [(drive.variable(name), value) for name, value in writes if drive.profile.has(name)]
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


def _values(request: MeasureRequest, signal: Multisine, axis: Axis) -> Callable[[int], int]:
    """Value k of the stream in the excited object's raw unit."""
    if request.loop == "plant":
        peak = 10.0 * request.amplitude  # ‰ of the rated current
        return lambda k: round(peak * signal.value(k))
    base = axis.user(request.base_speed_rad_s)
    swing = base * request.amplitude / 100.0
    return lambda k: round(base + swing * signal.value(k))


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


def _record(drive: Drive, request: MeasureRequest, signal: Multisine, watch: Watch, report: Report) -> list[Capture]:
    """Recordings of whole periods until ``request.periods`` are there (or the watch stops the axis)."""
    block = _block(signal)
    definition = CaptureDefinition(
        channels=_channels(request), period_us=RECORD_PERIOD_US, samples=2, timeout_s=RECORDING_TIMEOUT_S
    )
    capacity = _capacity(drive, definition)
    per_recording = max(1, min(request.periods, (capacity - 1) // block))
    session = session_of(drive)
    identity = DriveIdentity(bus="", node=drive.node, device=drive.profile.device)
    captures: list[Capture] = []
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
        try:
            captures.append(_recording(session, plan, identity, watch.halt))
        except Cancelled:
            break
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
    axis: Axis,
    captures: list[Capture],
    gains: dict[str, Any] | None,
    aborted: str | None,
    left: str | None,
) -> dict[str, Any]:
    """The result dict (contract of issue #16); an aborted measurement has no points."""
    if left is not None:
        aborted = f"{aborted}; {left}" if aborted else left
    points: list[estimate.Point] = [] if aborted else _estimate(request, signal, axis, captures)
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
            "periods": sum(len(c.columns[0]) // _block(signal) for c in captures),
            "sample_period_us": RECORD_PERIOD_US,
            "source": "recorder",
        },
        "points": shown,
        "markers": markers.markers_of(request.loop, shown),
        "plant_fit": estimate.rigid_fit(points) if request.loop == "plant" and points else None,
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
            inputs += estimate.block_lines([axis.rad(value) for value in columns[0]], harmonics, block)
        outputs += estimate.speed_lines(estimate.position_lines(positions, harmonics, block), frequencies)
    if request.loop == "plant":
        return estimate.by_reference(reference, inputs, outputs, frequencies)
    return estimate.h1(inputs, outputs, frequencies)


def _advanced(row: estimate.Lines, frequencies: list[float], seconds: float) -> estimate.Lines:
    return [value * cmath.exp(2j * math.pi * f * seconds) for value, f in zip(row, frequencies, strict=True)]
