"""The verification after auto-tuning (docs/commissioning.md §5): speed steps, and when the tuning ran in a position
mode (it computed the position loop too) a position step, recorded with the capture service while the axis is
enabled through the motion guard (the run's actor is the axis's armed controller), then disabled again with every
value it changed put back.

The steps are small enough that the current stays below its limit (a saturated loop says nothing about its
bandwidth): Δω = I_step·Kt / (J·ω) of the requested bandwidth, from the identified inertia and the torque constant,
I_step the rated current but at most half the max current (on a drive that gives its rated torque 6076h rather
than a torque constant: that torque, at most half the max current's). They start from a small base speed, not from
rest (Coulomb friction, see BASE_SHARE), and alternate in direction. A drive's own auto-tuning without a recorder
gets no verification (``skipped`` says why); the tool's tuning (``verify_steps``) records such a drive by
synchronous TPDOs at 1 ms instead (the encoTRive).
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable, Mapping, Sequence
from typing import TYPE_CHECKING, Any

from servostudio.drive.access import Drive
from servostudio.drive.cia402 import State
from servostudio.drive.control import set_state
from servostudio.services.procedures.commutation import verify_commutation
from servostudio.services.procedures.recording import record
from servostudio.services.procedures.run import disable, read_values, restore
from servostudio.services.procedures.stepmetrics import Recording, mean_bandwidth, step_metrics, window
from servostudio.services.procedures.units import TWO_PI, speed_rad_s, units_per_revolution, user_speed
from servostudio.services.scope import Capture, CaptureDefinition, Trigger
from servostudio.services.scope.plan import object_key

if TYPE_CHECKING:
    from servostudio.services.procedures.run import ProcedureRun

MODE_PP, MODE_PV = 1, 3
#: CiA 402 profile position, interpolated position, cyclic synchronous position: a tuning in one of these computed
#: the position loop too, and its verification steps the position as well
POSITION_MODES = (1, 7, 8)
PERIOD_US = 500.0
SAMPLES = 800  # 0.4 s: a slow loop (anti-resonance filter) settles within it
#: without a recorder: synchronous TPDOs at the SYNC producer's fastest period, over the same 0.4 s
STREAM_PERIOD_US = 1000.0
STREAM_SAMPLES = 400
PRE_TRIGGER_PCT = 5.0
#: the ramps of a step: a fraction of a second to full speed is a step for a loop of 50 Hz and more
STEP_RAMP_REV_S2 = 20000.0
SETTLE_S = 0.2
RETURN_WAIT = 3.0
POSITION_STEP_REV = 0.05
DEFAULT_STEP_RAD_S = 5.0
#: the step's travel over the recording stays below a revolution (the manual: one free revolution)
MAX_STEP_RAD_S = 9.0
#: the step's current, the smaller of these shares of the rated and of the max current: the larger the step, the
#: smaller the speed measurement's quantisation next to it (at ½ of the rated current one step read 53–80 Hz of a
#: 62 Hz loop, at the full rated current 60–64 Hz), and the loop stays clear of its current limit
STEP_CURRENT_SHARE = 1.0
STEP_MAX_CURRENT_SHARE = 0.5
#: the step starts from this share of its size in speed, never from standstill: Coulomb friction changes sign
#: at zero speed, which makes a step from rest a load step too (measured: 0.64-0.75 x the loop's bandwidth)
BASE_SHARE = 0.25
RPM = 60.0 / TWO_PI
#: recorded speed steps, alternating in direction (the travel nets out; the mean of their frequency responses
#: averages the speed measurement's quantisation noise out of the bandwidth)
SPEED_STEPS = 2
#: ... and by TPDOs more of them: a sample of 0x606C is the drive's latest up to one SYNC period old, a jitter each
#: step has its own (measured on the simulated encoTRive: one step 57-80 Hz of a 68 Hz loop)
STREAM_SPEED_STEPS = 6


def verify(run: ProcedureRun, result: dict[str, object], options: Mapping[str, Any]) -> dict[str, object] | None:
    """The verification of a procedure that has one; None for the others."""
    if run.name == "auto_phasing":
        run.progress("verifying", "done", "verification: commutation (torque per ampere)", None)
        return verify_commutation(run.drive)
    if run.name != "auto_tuning":
        return None
    drive = run.drive
    if drive.profile.recorder is None:
        return {"speed_step": None, "position_step": None, "skipped": f"the {drive.profile.device} has no recorder"}
    return verify_steps(run, result, options)


def verify_steps(run: ProcedureRun, result: dict[str, object], options: Mapping[str, Any]) -> dict[str, object]:
    """The speed steps, and a position step after a tuning in a position mode, recorded by the drive's recorder or
    (without one) by synchronous TPDOs; the axis left disabled with every value the steps changed put back."""
    drive = run.drive
    run.progress("verifying", "done", "verification: speed step", None)
    saved = read_values(drive, list(drive.profile.procedures.verification_objects))
    start = int(drive.read("position_actual").raw)
    try:
        speed = _speed_step(drive, _step_size(drive, result, options))
        position = _position_step(drive) if run.description.mode in POSITION_MODES else None
        _back_to(drive, start)
    finally:
        disable(drive)
        restore(drive, saved)
    return {"speed_step": speed, "position_step": position}


def _step_size(drive: Drive, result: dict[str, object], options: Mapping[str, Any]) -> float:
    """rad/s of the speed step."""
    identified = result.get("identified")
    inertia = identified.get("inertia_kgm2") if isinstance(identified, dict) else None
    torque = _step_torque(drive)
    if not isinstance(inertia, float) or inertia <= 0 or torque is None:
        return DEFAULT_STEP_RAD_S
    omega = TWO_PI * float(options.get("bandwidth", 75))
    step = torque / (inertia * omega)
    return min(max(step, 1.0), MAX_STEP_RAD_S) if step > 0 else DEFAULT_STEP_RAD_S


def _step_torque(drive: Drive) -> float | None:
    """N·m of the step: the step current × the motor's torque constant, else (the encoTRive) the motor rated torque
    6076h at most STEP_MAX_CURRENT_SHARE of the max current 6073h (‰ of the rated); None: neither is known."""
    name, profile = drive.profile.procedures.torque_constant, drive.profile
    if name is not None and profile.has("rated_current"):
        return _step_current(drive) * float(drive.read(name).physical)
    if not profile.has("rated_torque"):
        return None
    rated = float(drive.read("rated_torque").raw) / 1000.0
    if not profile.has("max_current"):
        return STEP_CURRENT_SHARE * rated if rated > 0 else None
    maximum = rated * float(drive.read("max_current").raw) / 1000.0
    return min(STEP_CURRENT_SHARE * rated, STEP_MAX_CURRENT_SHARE * maximum) if rated > 0 else None


def _step_current(drive: Drive) -> float:
    """A of the step: STEP_CURRENT_SHARE of the rated current, at most STEP_MAX_CURRENT_SHARE of the max current
    (0x6073 is % of the rated current)."""
    rated = float(drive.read("rated_current").physical)
    if not drive.profile.has("max_current"):
        return STEP_CURRENT_SHARE * rated
    maximum = rated * float(drive.read("max_current").physical) / 100.0
    return min(STEP_CURRENT_SHARE * rated, STEP_MAX_CURRENT_SHARE * maximum)


def _speed_step(drive: Drive, step_rad_s: float) -> dict[str, object]:
    """Profile velocity, enabled at standstill, then SPEED_STEPS recorded steps of the target, alternating in
    direction; the first step's metrics, and the bandwidth of their mean frequency response."""
    ramp = _acceleration(drive, STEP_RAMP_REV_S2)
    base = round(user_speed(drive, BASE_SHARE * step_rad_s))
    top = base + round(user_speed(drive, step_rad_s))
    values = {"target_velocity": 0, "profile_acceleration": ramp, "profile_deceleration": ramp}
    _prepare(drive, MODE_PV, values | _speed_limit(drive, 2 * abs(top)) | _ramp_limits(drive, ramp))
    recordings = []
    try:
        for n in range(SPEED_STEPS if drive.profile.recorder is not None else STREAM_SPEED_STEPS):
            sign = 1 if n % 2 == 0 else -1
            recordings.append(_recorded_step(drive, sign * base, sign * top))
    finally:
        drive.write("target_velocity", 0)
    return _speed_result(recordings, _measurement_filters(drive), aligned=drive.profile.recorder is not None)


def _speed_result(recordings: list[Recording], filters: tuple[float, ...], aligned: bool = True) -> dict[str, object]:
    """The metrics of the first step that settled, and the bandwidth of the mean frequency response of all that
    settled: a step that did not (a limit switch in its way, an axis that oscillates) says nothing about the loop's
    bandwidth, and is listed with None.  Steps recorded by TPDOs (not ``aligned``: each has its own fraction of a
    period between set-point and sample, so their mean response is smeared) give the median of their bandwidths."""
    metrics = [step_metrics(*recording, filters) for recording in recordings]
    settled = [n for n, one in enumerate(metrics) if one.settling_time_s is not None]
    windows = [window(*recordings[n]) for n in settled]
    shown = settled[0] if settled else 0
    found = [one.bandwidth_hz for one in metrics if one.settling_time_s is not None and one.bandwidth_hz is not None]
    if aligned:
        bandwidth = mean_bandwidth([w for w in windows if w is not None], filters) if settled else None
    else:
        bandwidth = round(statistics.median(found), 1) if found else None
    return {
        **metrics[shown].as_dict(),
        "bandwidth_hz": bandwidth,
        "bandwidth_steps_hz": [one.bandwidth_hz if n in settled else None for n, one in enumerate(metrics)],
        "capture": _shown(*recordings[shown], "rpm"),
    }


def _recorded_step(drive: Drive, start: int, end: int) -> Recording:
    """One recorded step of the target velocity from ``start`` to ``end`` (user units/s), in rpm. The axis runs only
    while the recorder waits and records: at ``start`` for SETTLE_S, then at ``end`` until the recording is complete,
    then it stops (while the recording is read, the axis would travel on)."""

    def step() -> None:
        drive.write("target_velocity", start)
        time.sleep(SETTLE_S)
        drive.write("target_velocity", end)

    definition = CaptureDefinition(
        channels=("target_velocity", "velocity_actual"),
        trigger=Trigger(_source(drive, "target_velocity"), "rising" if end > start else "falling", (start + end) / 2),
        pre_trigger_pct=PRE_TRIGGER_PCT,
        timeout_s=10.0,
        **_timing(drive),
    )
    capture = _record(drive, definition, step, lambda: drive.write("target_velocity", 0))
    rpm = speed_rad_s(drive, 1.0) * RPM  # one user unit/s in rpm
    reference = [float(value) * rpm for value in capture.physical(0)]
    return capture.times_s(), reference, [float(value) * rpm for value in capture.physical(1)]


def _position_step(drive: Drive) -> dict[str, object]:
    """Profile position: a small relative move at a speed and ramps far beyond the loop's; overshoot of the
    actual position past the target."""
    disable(drive)
    units = units_per_revolution(drive)
    ramp = units * STEP_RAMP_REV_S2
    values = {"profile_velocity": units * 50, "profile_acceleration": ramp, "profile_deceleration": ramp}
    _prepare(drive, MODE_PP, values | _speed_limit(drive, units * 50))
    start = float(drive.read("position_actual").raw)
    distance = round(units * POSITION_STEP_REV)
    definition = CaptureDefinition(
        channels=("position_demand", "position_actual"),
        trigger=Trigger(_source(drive, "position_demand"), "rising", start + distance / 2),
        pre_trigger_pct=PRE_TRIGGER_PCT,
        timeout_s=10.0,
        **_timing(drive),
    )
    capture = _record(drive, definition, lambda: _move(drive, distance), lambda: None)
    times = capture.times_s()
    reference = [float(value) - start for value in capture.physical(0)]
    response = [float(value) - start for value in capture.physical(1)]
    metrics = step_metrics(times, reference, response)
    return {**metrics.as_dict(), "capture": _shown(times, reference, response, "user position units")}


def _back_to(drive: Drive, start: int) -> None:
    """Profile position back to where the verification started (the tuned loop holds it), within a second."""
    disable(drive)
    units = units_per_revolution(drive)
    values = {"profile_velocity": units, "profile_acceleration": units * 20, "profile_deceleration": units * 20}
    _prepare(drive, MODE_PP, values | _speed_limit(drive, units))
    drive.write("target_position", start)
    drive.write("controlword", 0x0F | 0x10 | 0x20)
    drive.write("controlword", 0x0F | 0x20)
    deadline = time.monotonic() + RETURN_WAIT
    while time.monotonic() < deadline and abs(int(drive.read("position_actual").raw) - start) > units / 100:
        time.sleep(0.02)


def _prepare(drive: Drive, mode: int, values: Mapping[str, float]) -> None:
    writes = [(drive.variable("modes_of_operation"), mode)]
    writes += [(drive.variable(name), _fit(drive, name, value)) for name, value in values.items()]
    drive.submit_write_all(writes).future.result()
    set_state(drive, State.OPERATION_ENABLED)
    time.sleep(SETTLE_S)


def _timing(drive: Drive) -> dict[str, Any]:
    """Period, samples and source of a step's recording: the drive's recorder, else synchronous TPDOs."""
    if drive.profile.recorder is not None:
        return {"period_us": PERIOD_US, "samples": SAMPLES}
    return {"period_us": STREAM_PERIOD_US, "samples": STREAM_SAMPLES, "source": "tpdo"}


def _source(drive: Drive, name: str) -> str:
    """The trigger's object: a name for the recorder, the channel's address for TPDOs (the server matches the
    channels it receives by address)."""
    return name if drive.profile.recorder is not None else object_key(drive.variable(name))


def _acceleration(drive: Drive, rev_s2: float) -> float:
    """An acceleration in the drive's own unit (the profile's, e.g. the encoTRive's rpm/s, else units/s²)."""
    unit = drive.profile.acceleration_unit_rad_s2
    return rev_s2 * TWO_PI / unit if unit else rev_s2 * units_per_revolution(drive)


def _ramp_limits(drive: Drive, ramp: float) -> dict[str, float]:
    """Raise the maximum acceleration and deceleration (the encoTRive's 60C5h / 60C6h bound the profile's ramps) to
    the step's, if they are lower (put back afterwards): a ramp the drive slowed down would be part of the
    measured loop."""
    names = [name for name in ("max_acceleration", "max_deceleration") if drive.profile.has(name)]
    return {name: ramp for name in names if float(drive.read(name).raw) < ramp}


def _speed_limit(drive: Drive, needed: float) -> dict[str, float]:
    """Raise the profile's speed limit (0x607F) to what the step needs, if it is lower (put back afterwards)."""
    if not drive.profile.has("max_profile_velocity"):
        return {}
    present = float(drive.read("max_profile_velocity").raw)
    return {} if present >= needed else {"max_profile_velocity": needed}


def _fit(drive: Drive, name: str, value: float) -> int:
    """A ramp or speed within its object's range."""
    high = drive.variable(name).high
    return int(min(value, high)) if high is not None else int(value)


def _move(drive: Drive, distance: int) -> None:
    """A relative set-point taken at once (control word bits 4 new set-point, 5 change at once, 6 relative)."""
    drive.write("target_position", distance)
    drive.write("controlword", 0x0F | 0x10 | 0x20 | 0x40)
    drive.write("controlword", 0x0F | 0x20 | 0x40)


def _record(
    drive: Drive, definition: CaptureDefinition, act: Callable[[], object], done: Callable[[], object]
) -> Capture:
    """Act once the recorder waits for its trigger (a trigger while it fills its pre-trigger samples would be
    missed), end the step once the recording is complete, and read it."""

    def report(event: dict[str, object]) -> None:
        if event.get("stage") == "waiting":
            act()
        elif event.get("stage") == "done":
            done()

    return record(drive, definition, report)


def _measurement_filters(drive: Drive) -> tuple[float, ...]:
    """The cut-offs (Hz) of the first-order filters between the shaft's speed and the recorded 0x606C."""
    return tuple(value for value in (_monitor_filter(drive), _loop_speed_filter(drive)) if value is not None)


def _monitor_filter(drive: Drive) -> float | None:
    name = drive.profile.procedures.speed_monitor_filter
    if name is None or not drive.profile.has(name):
        return None
    value = float(drive.read(name).physical)
    return value if value > 0 else None


def _loop_speed_filter(drive: Drive) -> float | None:
    procedures = drive.profile.procedures
    name = procedures.speed_measurement_filter
    loop = drive.profile.speed_loop
    if name is None and loop is not None and loop.speed_filter is None and loop.inertia_setting is not None:
        return 1.0 / (TWO_PI * loop.fixed_speed_filter_s)  # the encoTRive's fixed speed filter
    if name is None or not drive.profile.has(name):
        return None
    tau = procedures.speed_measurement_filter_s.get(int(drive.read(name).raw))
    return 1.0 / (TWO_PI * tau) if tau else None


def _shown(
    times: Sequence[float], reference: Sequence[float], response: Sequence[float], unit: str
) -> dict[str, object]:
    return {
        "time_s": [round(value, 6) for value in times],
        "reference": [round(value, 3) for value in reference],
        "response": [round(value, 3) for value in response],
        "unit": unit,
    }
