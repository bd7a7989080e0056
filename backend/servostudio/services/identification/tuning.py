"""Gains for a requested speed-loop bandwidth from the identified plant (docs/identification.md § Tuning), written
to the drive's own gain objects through its device profile (``services.frequency.speed_loop``: physical values in,
raw values and the gain multiplier out, through the drive's gate), then verified by the auto-tuning's speed step
whose bandwidth is measured from the recording (``services.procedures.verification``).

The rule is auto-tuning's (docs/control-loops.md §4), in physical units: ωc = κ·2π·f, KPv = J·ωc/Kt,
KIv = KPv·ωc/4, KCv = KDv = 0, no integrator leak; the position feed-forwards KAv = J/Kt and KBv = B/Kt (minimum
following error). κ is the measured 0.667 / 0.643 / 0.611 at 50 / 75 / 100 Hz, linear between them and held beyond.
A drive that derives its gains from an inertia setting (the encoTRive's Θi: crossover (Θi/J)·ωd) gets the Θi that
puts its crossover at ωc = κ·2π·f with its own loop's κ (the profile's ``crossover_factors``): Θi = J·ωc/ωd.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from typing import Any

from servostudio.drive.access import Drive
from servostudio.drive.profiles.procedures import ProcedureDescription
from servostudio.drive.profiles.speed_loop import InertiaSetting
from servostudio.errors import InvalidInput
from servostudio.services.cancel import Cancellation
from servostudio.services.frequency.speed_loop import INERTIA_KEY, description, read_speed_loop, write_speed_loop
from servostudio.services.procedures.run import ProcedureRun
from servostudio.services.procedures.verification import verify_steps

KAPPA = ((50.0, 0.667), (75.0, 0.643), (100.0, 0.611))
BANDWIDTHS = (20.0, 200.0)
#: the verification of a drive without auto-tuning of its own: the speed step only (no position gains computed)
STEP_ONLY = ProcedureDescription("Speed-step verification", "", "", moves=True, preconditions=())


class BadTuning(InvalidInput):
    """A bandwidth out of range, or a plant the gains cannot be computed from."""


def check_tuning(drive: Drive, bandwidth_hz: float | None) -> None:
    """Refuse before the experiment: a bandwidth out of range, or a drive without gain objects (``NoSpeedLoop``)."""
    if bandwidth_hz is None:
        return
    low, high = BANDWIDTHS
    if not low <= bandwidth_hz <= high:
        raise BadTuning(f"bandwidth {bandwidth_hz:g} Hz: use {low:g}..{high:g} Hz")
    description(drive)


def crossover(bandwidth_hz: float, points: tuple[tuple[float, float], ...] = KAPPA) -> float:
    """ωc of the rule, rad/s (κ of ``points``: linear between them, held beyond)."""
    if bandwidth_hz <= points[0][0]:
        kappa = points[0][1]
    elif bandwidth_hz >= points[-1][0]:
        kappa = points[-1][1]
    else:
        (f0, k0), (f1, k1) = next((a, b) for a, b in itertools.pairwise(points) if a[0] <= bandwidth_hz <= b[0])
        kappa = k0 + (k1 - k0) * (bandwidth_hz - f0) / (f1 - f0)
    return kappa * 2.0 * math.pi * bandwidth_hz


def gains(identified: dict[str, Any], torque_constant: float, bandwidth_hz: float) -> dict[str, float]:
    """The physical gains of the rule for this plant."""
    inertia, viscous = _inertia(identified), identified.get("viscous_friction_nms_per_rad")
    if torque_constant <= 0:
        raise BadTuning("the drive's torque constant is not positive: no gains computed")
    omega = crossover(bandwidth_hz)
    kp = inertia * omega / torque_constant
    return {"kp_a_per_rad_s": kp, "ki_a_per_rad": kp * omega / 4, "kc_a_per_rad_s": 0.0, "kd_a_per_rad_s2": 0.0,
              "ki_leak_hz": 0.0, "ka_a_per_rad_s2": inertia / torque_constant,
              "kb_a_per_rad_s": max(float(viscous or 0.0), 0.0) / torque_constant}  # fmt: skip


def inertia_setting(identified: dict[str, Any], setting: InertiaSetting, bandwidth_hz: float) -> float:
    """Θi in kg·m² for the bandwidth: the drive's crossover (Θi/J)·ωd at ωc = κ·2π·f, Θi = J·ωc/ωd, κ of this loop
    (the viscous friction plays no part: the drive has no friction compensation)."""
    omega = crossover(bandwidth_hz, setting.crossover_factors)
    return _inertia(identified) * omega / setting.design_crossover


def tune(drive: Drive, identified: dict[str, Any], bandwidth_hz: float,
         report: Callable[[dict[str, object]], None]) -> dict[str, object]:  # fmt: skip
    """Compute, write and verify; the result has the gains before → after and the measured step."""
    wanted = _wanted(drive, read_speed_loop(drive), identified, bandwidth_hz)
    report({"phase": "tuning", "fraction": 0.96, "message": f"gains for {bandwidth_hz:g} Hz"})
    written = write_speed_loop(drive, wanted)
    own = drive.profile.procedures.get("auto_tuning")
    run = ProcedureRun(drive, "auto_tuning", own or STEP_ONLY, _progress(report), Cancellation())
    step = verify_steps(run, {"identified": identified}, {"bandwidth": bandwidth_hz})
    return {
        "bandwidth_hz": bandwidth_hz,
        "gains": {"before": _physical(written["before"]), "after": _physical(written["after"])},
        "verification": step,
    }


def _wanted(drive: Drive, loop: dict[str, Any], identified: dict[str, Any], bandwidth_hz: float) -> dict[str, float]:
    """What to write: the inertia setting where the drive derives its gains from one, else the gains it has."""
    setting = description(drive).inertia_setting
    if setting is not None and INERTIA_KEY in loop["writable"]:
        return {INERTIA_KEY: inertia_setting(identified, setting, bandwidth_hz)}
    torque_constant = loop.get("torque_constant_nm_per_a")
    if not isinstance(torque_constant, float):
        raise BadTuning(f"node {drive.node}: the {drive.profile.device} has no torque constant: no gains in A from N·m")
    found = gains(identified, torque_constant, bandwidth_hz)
    return {key: value for key, value in found.items() if key in loop["writable"]}


def _inertia(identified: dict[str, Any]) -> float:
    inertia = identified.get("inertia_kgm2")
    if not isinstance(inertia, float) or inertia <= 0:
        raise BadTuning("the identified inertia is not positive: no gains computed")
    return inertia


def _physical(loop: dict[str, Any]) -> dict[str, Any]:
    return {key: value for key, value in loop.items() if key not in ("raw", "writable", "speed_filter_choices_s")}


def _progress(report: Callable[[dict[str, object]], None]) -> Callable[[dict[str, object]], None]:
    return lambda event: report({"phase": "verifying", "fraction": 0.98, "message": str(event.get("message", ""))})
