"""The speed loop in physical units: a drive's raw gains and filters read as A/(rad/s), A/rad, Hz, s, and back.

One place converts, from the device profile's ``SpeedLoopDescription`` (docs/control-loops.md §1–2), for the
what-if model in the browser (docs/what-if.md), the identification's tuning and the frequency response's record of
the loop it measured.  A drive whose gains the drive derives itself from an inertia setting (the encoTRive's Θi,
docs/identification.md § Tuning) reads as those derived gains and takes only ``inertia_setting_kgm2``.  A drive
without any description (a generic CiA 402 drive) has no speed loop to read or write: both refuse with
:class:`NoSpeedLoop`.

Writes are validated completely before anything is sent (unknown key, negative or non-finite value, a raw value out
of its object's range, a speed filter the drive cannot select), and go through the drive's gate in one batch.  The
gain multiplier (KJv) is chosen as auto-tuning chooses it, the smallest ×2ᵏ that keeps every scaled gain in range;
when it changes, every gain it scales is rewritten so their physical values stay, ordered so the loop passes only
through gains at most the final ones (a larger multiplier is written after the gains, a smaller one before).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from servostudio.drive.access import Drive
from servostudio.drive.profiles.speed_loop import InertiaSetting, SpeedLoopDescription
from servostudio.drive.sdo import settle
from servostudio.errors import InvalidInput, NotFound
from servostudio.services.procedures.run import read_values

#: the largest multiplier exponent (KJv = 256·2⁷ = 32768 fits a U16)
MAX_MULTIPLIER_SHIFT = 7
FILTER_KEYS = ("current_filter_1_hz", "current_filter_2_hz", "current_filter_3_hz")
SPEED_FILTER_KEY = "speed_filter_s"
INERTIA_KEY = "inertia_setting_kgm2"


class NoSpeedLoop(NotFound):
    """The drive has no speed-loop gain objects (its loops are set in the factory)."""


class BadSpeedLoop(InvalidInput):
    """Speed-loop values refused before anything was written."""


def description(drive: Drive) -> SpeedLoopDescription:
    found = drive.profile.speed_loop
    if found is None:
        raise NoSpeedLoop(
            f"node {drive.node}: the {drive.profile.device} has no speed-loop gain objects the tool knows: "
            "nothing to read, model or write"
        )
    return found


def read_speed_loop(drive: Drive) -> dict[str, Any]:
    """The speed loop in physical units, JSON-ready (contract of issue #16 §3); ``raw`` holds what was read."""
    loop = description(drive)
    raw = _read_raw(drive, loop)
    multiplier = _multiplier(loop, raw)
    result: dict[str, Any] = {
        "device": drive.profile.device,
        "control_period_s": loop.control_period_s,
        "torque_constant_nm_per_a": _torque_constant(loop, raw),
        "gain_multiplier": multiplier,
    }
    for key, scale in loop.gains.items():
        result[key] = float(raw.get(scale.object, 0)) * scale.unit * (multiplier if scale.scaled else 1.0)
    result.update(_derived(loop.inertia_setting, raw))
    for key in ("kp_a_per_rad_s", "ki_a_per_rad", "ki_leak_hz", "kc_a_per_rad_s", "kd_a_per_rad_s2"):
        result.setdefault(key, 0.0)
    result["current_filters_hz"] = [float(raw.get(name, 0)) for name in loop.current_filters if name in raw]
    result[SPEED_FILTER_KEY] = _speed_filter_s(loop, raw)
    result["speed_filter_choices_s"] = sorted(loop.speed_filter_s.values()) if loop.speed_filter is not None else []
    result["writable"] = writable(drive)
    result["raw"] = raw
    return result


def writable(drive: Drive) -> list[str]:
    """The physical keys ``raw_writes`` accepts for this drive."""
    loop = description(drive)
    keys = [key for key, scale in loop.gains.items() if drive.profile.has(scale.object)]
    keys += [key for key, name in zip(FILTER_KEYS, loop.current_filters, strict=False) if drive.profile.has(name)]
    if loop.speed_filter is not None and drive.profile.has(loop.speed_filter):
        keys.append(SPEED_FILTER_KEY)
    if loop.inertia_setting is not None and drive.profile.has(loop.inertia_setting.object):
        keys.append(INERTIA_KEY)
    return keys


def raw_writes(drive: Drive, physical: Mapping[str, float]) -> list[tuple[str, int]]:
    """The (semantic name, raw value) writes that give the drive these physical values, validated and in range;
    nothing is sent.  Keys not given keep their values."""
    loop = description(drive)
    _check_keys(drive, physical)
    raw = _read_raw(drive, loop)
    writes = _gain_writes(loop, raw, physical)
    writes += _filter_writes(loop, physical)
    writes += _inertia_writes(loop.inertia_setting, physical)
    for name, value in writes:
        drive.prepare_write(name, value)  # the dictionary's type and range, before anything is sent
    return writes


def write_speed_loop(drive: Drive, physical: Mapping[str, float]) -> dict[str, Any]:
    """Write physical speed-loop values through the drive's gate; ``before`` / ``after`` as read back."""
    before = read_speed_loop(drive)
    writes = raw_writes(drive, physical)
    if writes:
        settle(drive.submit_write_all([(drive.variable(name), value) for name, value in writes]).future)
    return {"before": before, "after": read_speed_loop(drive), "written": [list(write) for write in writes]}


def _read_raw(drive: Drive, loop: SpeedLoopDescription) -> dict[str, int]:
    names = [scale.object for scale in loop.gains.values()] + list(loop.current_filters)
    names += [name for name in (loop.multiplier, loop.speed_filter, loop.torque_constant) if name is not None]
    if loop.inertia_setting is not None:
        setting = loop.inertia_setting
        names += [setting.object, setting.rated_torque, setting.rated_current]
    return {name: int(value) for name, value in read_values(drive, names).items() if isinstance(value, int)}


def _multiplier(loop: SpeedLoopDescription, raw: Mapping[str, int]) -> float:
    if loop.multiplier is None or loop.multiplier not in raw:
        return 1.0
    return raw[loop.multiplier] / loop.multiplier_one


def _torque_constant(loop: SpeedLoopDescription, raw: Mapping[str, int]) -> float | None:
    if loop.inertia_setting is not None:
        return _rated_constant(loop.inertia_setting, raw)
    if loop.torque_constant is None or loop.torque_constant not in raw:
        return None
    return raw[loop.torque_constant] * loop.torque_constant_unit


def _rated_constant(setting: InertiaSetting, raw: Mapping[str, int]) -> float | None:
    """Kt = rated torque / rated current, N·m/A (None where either is missing or 0)."""
    torque = raw.get(setting.rated_torque, 0) * setting.rated_torque_unit
    current = raw.get(setting.rated_current, 0) * setting.rated_current_unit
    return torque / current if torque > 0 and current > 0 else None


def _derived(setting: InertiaSetting | None, raw: Mapping[str, int]) -> dict[str, float]:
    """The inertia setting and the gains the drive derives from it: KPv = Θi·ωd/Kt, KIv = KPv·ωd/8, KAv = Θi/Kt."""
    if setting is None or setting.object not in raw:
        return {}
    inertia = raw[setting.object] * setting.unit_kgm2
    constant = _rated_constant(setting, raw)
    if constant is None:
        return {INERTIA_KEY: inertia}
    kp = inertia * setting.design_crossover / constant
    zero = setting.design_crossover / setting.integral_divisor
    return {INERTIA_KEY: inertia, "kp_a_per_rad_s": kp, "ki_a_per_rad": kp * zero,
            "ka_a_per_rad_s2": inertia / constant}  # fmt: skip


def _inertia_writes(setting: InertiaSetting | None, physical: Mapping[str, float]) -> list[tuple[str, int]]:
    if setting is None or INERTIA_KEY not in physical:
        return []
    return [(setting.object, _count_of(physical[INERTIA_KEY] / setting.unit_kgm2, INERTIA_KEY, 0xFFFFFFFF))]


def _speed_filter_s(loop: SpeedLoopDescription, raw: Mapping[str, int]) -> float:
    if loop.speed_filter is None or loop.speed_filter not in raw:
        return loop.fixed_speed_filter_s
    return loop.speed_filter_s.get(raw[loop.speed_filter], loop.fixed_speed_filter_s)


def _check_keys(drive: Drive, physical: Mapping[str, float]) -> None:
    allowed = writable(drive)
    unknown = sorted(set(physical) - set(allowed))
    if unknown:
        raise BadSpeedLoop(
            f"node {drive.node}: {', '.join(unknown)} not writable on the {drive.profile.device} "
            f"(it takes {', '.join(allowed)})"
        )
    for key, value in physical.items():
        if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value) or value < 0:
            raise BadSpeedLoop(f"node {drive.node}: {key} = {value!r}: give a finite value ≥ 0")


def _gain_writes(
    loop: SpeedLoopDescription, raw: Mapping[str, int], physical: Mapping[str, float]
) -> list[tuple[str, int]]:
    """Raw gains for the physical ones, with the multiplier that keeps every scaled gain in range."""
    old = _multiplier(loop, raw)
    values = {
        key: float(physical.get(key, float(raw.get(scale.object, 0)) * scale.unit * (old if scale.scaled else 1.0)))
        for key, scale in loop.gains.items()
        if scale.object in raw or key in physical
    }
    new = _choose_multiplier(loop, values) if loop.multiplier in raw else old
    rewrite = {key for key, scale in loop.gains.items() if scale.scaled} if new != old else set()
    gains = [
        (scale.object, _count(values[key] / (scale.unit * (new if scale.scaled else 1.0)), key))
        for key, scale in loop.gains.items()
        if key in values and (key in physical or key in rewrite)
    ]
    if new == old or loop.multiplier is None:
        return gains
    multiplier = (loop.multiplier, round(new * loop.multiplier_one))
    return [*gains, multiplier] if new > old else [multiplier, *gains]


def _choose_multiplier(loop: SpeedLoopDescription, values: Mapping[str, float]) -> float:
    scaled = [values[key] / scale.unit for key, scale in loop.gains.items() if scale.scaled and key in values]
    largest = max(scaled, default=0.0)
    for shift in range(MAX_MULTIPLIER_SHIFT + 1):
        if largest / 2**shift < 0xFFFF + 0.5:  # compared before rounding: a huge value (even inf) is refused
            return float(2**shift)
    raise BadSpeedLoop(f"a speed-loop gain of {largest:.4g} counts is out of range even with the largest multiplier")


def _count(value: float, key: str) -> int:
    return _count_of(value, key, 0xFFFF)


def _count_of(value: float, key: str, high: int) -> int:
    if not value < high + 0.5:
        raise BadSpeedLoop(f"{key}: {value:.6g} counts is out of range (0..{high})")
    return round(value)


def _filter_writes(loop: SpeedLoopDescription, physical: Mapping[str, float]) -> list[tuple[str, int]]:
    writes = [
        (name, round(physical[key]))
        for key, name in zip(FILTER_KEYS, loop.current_filters, strict=False)
        if key in physical
    ]
    if SPEED_FILTER_KEY in physical and loop.speed_filter is not None:
        writes.append((loop.speed_filter, _speed_filter_code(loop, physical[SPEED_FILTER_KEY])))
    return writes


def _speed_filter_code(loop: SpeedLoopDescription, seconds: float) -> int:
    for code, tau in loop.speed_filter_s.items():
        if math.isclose(tau, seconds, rel_tol=1e-6):
            return code
    choices = ", ".join(f"{tau:g}" for tau in loop.speed_filter_s.values())
    raise BadSpeedLoop(f"{SPEED_FILTER_KEY} = {seconds!r}: this drive's speed filter is one of {choices} s")
