"""The verification after auto-phasing: does the commutation give the torque per ampere it should?

With a commutation error δ the motor gives cos δ of its torque per ampere. The check measures δ without knowing the
inertia or the friction: three short torque pulses in profile torque mode, with the sensor offset found and with it
shifted by ±45° electrical, each acceleration recorded by the capture service and fitted. Each is
a(φ) = (K·cos(δ + φ) − T_friction) / J, so

    a(−45°) − a(+45°)        = (K/J) · 2 sin 45° · sin δ
    2·a(0) − a(−45°) − a(+45°) = (K/J) · 2 (1 − cos 45°) · cos δ

and friction and inertia cancel: δ = atan2(first / (2 sin 45°), second / (2 (1 − cos 45°))). The check passes when
cos δ ≥ 0.98 (issue #13). The offset is put back after the pulses, the drive is left disabled. The pulse current is
sized from the motor's own inertia (datasheet) so the axis stays slow: a ≈ 1500 rad/s² on the motor alone.
"""

from __future__ import annotations

import math
import time

from servostudio.drive.access import Drive
from servostudio.drive.cia402 import State
from servostudio.drive.control import set_state
from servostudio.services.procedures.recording import record
from servostudio.services.procedures.run import disable, read_values, restore
from servostudio.services.procedures.units import speed_rad_s
from servostudio.services.scope import CaptureDefinition, Trigger

MODE_PT = 4
SHIFT = 65536 // 8  # 45° electrical in sensor-offset units (65536 = one electrical turn)
PASS_RATIO = 0.98
PULSE_SAMPLES = 120
PERIOD_US = 250.0
PRE_TRIGGER_PCT = 10.0
#: the pulse lasts this much longer than the recording after its trigger (the trigger is a sample late)
PULSE_MARGIN = 1.2
#: the reverse torque after a pulse, as a share of the time the pulse was on (friction brakes the rest)
REVERSE_SHARE = 0.8
SKIP_S = 0.001  # the current's rise at the start of a pulse
TARGET_ACCELERATION = 1500.0  # rad/s², on the motor's own inertia
SLOPE = 1_000_000  # ‰/s: a torque step
STOP_WAIT = 1.0
REST_RAD_S = 0.5
#: (offset shift, direction) of the three pulses
PULSES = ((0, 1), (-SHIFT, -1), (SHIFT, 1))
OBJECTS = ("modes_of_operation", "target_torque", "torque_slope", "sensor_offset")


def verify_commutation(drive: Drive) -> dict[str, object]:
    """``{"torque_per_ampere_ratio", "passed", "error_deg"}``; a drive without a recorder: ``skipped``."""
    if drive.profile.recorder is None or not all(drive.profile.has(name) for name in OBJECTS):
        return {"torque_per_ampere_ratio": None, "passed": None, "skipped": "the drive has no recorder"}
    saved = read_values(drive, list(OBJECTS))
    offset = int(saved["sensor_offset"])  # type: ignore[call-overload]
    level = _pulse_level(drive)
    try:
        # alternate directions, so the axis ends near where it started
        accelerations = [_pulse(drive, (offset + shift) % 65536, sign * level) for shift, sign in PULSES]
    finally:
        disable(drive)
        restore(drive, saved)
    return _judged(*accelerations)


def _judged(centre: float, minus: float, plus: float) -> dict[str, object]:
    if min(centre, minus, plus) <= 0:
        reason = "the axis did not accelerate with every pulse (blocked, braked, at a limit switch?)"
        return {"torque_per_ampere_ratio": None, "passed": False, "error_deg": None, "reason": reason}
    sine = (minus - plus) / (2 * math.sin(math.pi / 4))
    cosine = (2 * centre - minus - plus) / (2 * (1 - math.cos(math.pi / 4)))
    error = math.atan2(sine, cosine)
    ratio = math.cos(error)
    return {"torque_per_ampere_ratio": round(ratio, 4), "passed": ratio >= PASS_RATIO,
            "error_deg": round(math.degrees(error), 2)}  # fmt: skip


def _pulse_level(drive: Drive) -> int:
    """The pulse's torque target, ‰ of the rated current: 1500 rad/s² on the motor alone, 5..30 % of rated."""
    procedures = drive.profile.procedures
    names = (procedures.motor_inertia, procedures.torque_constant)
    if None in names or not drive.profile.has("rated_current"):
        return 100
    inertia, constant = (float(drive.read(name).physical) for name in names if name is not None)
    rated = float(drive.read("rated_current").physical)
    if inertia <= 0 or constant <= 0 or rated <= 0:
        return 100
    return round(min(max(1000 * TARGET_ACCELERATION * inertia / constant / rated, 50), 300))


def _pulse(drive: Drive, offset: int, level: int) -> float:
    """One torque pulse (``level`` ‰, its sign the direction) with ``offset`` as the commutation; the fitted
    acceleration in the pulse's direction (rad/s²)."""
    writes = [("sensor_offset", offset), ("modes_of_operation", MODE_PT), ("target_torque", 0), ("torque_slope", SLOPE)]
    drive.submit_write_all([(drive.variable(name), value) for name, value in writes]).future.result()
    set_state(drive, State.OPERATION_ENABLED)
    edge = "rising" if level > 0 else "falling"
    definition = CaptureDefinition(
        channels=("target_torque", "velocity_actual"),
        period_us=PERIOD_US,
        samples=PULSE_SAMPLES,
        trigger=Trigger("target_torque", edge, level / 20),  # physical: % of the rated current
        pre_trigger_pct=PRE_TRIGGER_PCT,
        timeout_s=10.0,
    )

    def report(event: dict[str, object]) -> None:
        if event.get("stage") == "waiting":
            _push(drive, level)
            _stop(drive, abs(level))

    try:
        capture = record(drive, definition, report)
    finally:
        _stop(drive, abs(level))  # whatever became of the recording, the axis is at rest before it is disabled
    disable(drive)
    slope = _slope(drive, capture.times_s(), capture.physical(0), capture.physical(1), level)
    return slope if level > 0 else -slope


def _push(drive: Drive, level: int) -> None:
    """The pulse and its mirror, timed by the tool rather than by the recorder's status: the torque is on for the
    recording's post-trigger time (the first sample past the trigger is the pulse's start), then reversed for
    about as long as it was on, which takes most of the speed back (friction helps: a little shorter); ``_stop``
    takes the rest. A pulse that ends early shows in the recorded target, and only the samples at full torque are
    fitted."""
    drive.write("target_torque", level)
    began = time.monotonic()
    time.sleep(PULSE_SAMPLES * PERIOD_US * 1e-6 * (1 - PRE_TRIGGER_PCT / 100) * PULSE_MARGIN)
    drive.write("target_torque", -level)
    time.sleep((time.monotonic() - began) * REVERSE_SHARE)
    drive.write("target_torque", 0)


def _stop(drive: Drive, level: int) -> None:
    """Bring the axis to rest with reverse torque, each stage a quarter of the last (a bus round trip late, the
    reverse torque overshoots; the next, weaker stage takes that back), then no torque."""
    unit = speed_rad_s(drive, 1.0)
    stage = level
    while stage >= 1:
        speed = float(drive.read("velocity_actual").raw) * unit
        if abs(speed) < REST_RAD_S:
            break
        drive.write("target_torque", -stage if speed > 0 else stage)
        deadline = time.monotonic() + STOP_WAIT
        while time.monotonic() < deadline and float(drive.read("velocity_actual").raw) * unit * speed > 0:
            pass  # one read after the other: the reverse torque must end as soon as the axis stands
        stage //= 4
    drive.write("target_torque", 0)


def _slope(drive: Drive, times: list[float], target: list, speed: list, level: int) -> float:
    """Least-squares slope of the speed (rad/s) while the pulse's torque was applied."""
    sign = 1 if level > 0 else -1
    top = max(sign * float(value) for value in target)
    unit = speed_rad_s(drive, 1.0)
    points = [
        (t, float(v) * unit)
        for t, r, v in zip(times, target, speed, strict=True)
        if sign * float(r) >= top and t >= SKIP_S
    ]
    if len(points) < 3:
        return 0.0
    mean_t = sum(t for t, _ in points) / len(points)
    mean_v = sum(v for _, v in points) / len(points)
    spread = sum((t - mean_t) ** 2 for t, _ in points)
    return sum((t - mean_t) * (v - mean_v) for t, v in points) / spread if spread else 0.0
