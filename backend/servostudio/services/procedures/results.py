"""A finished procedure's result as the pinned CLI JSON (issue #13 item 6): the objects it changed before and after,
for auto-phasing the commutation found, for auto-tuning the identified plant (0x3428) with the inertia ratio.

Values are raw, keyed by the profile's semantic names (``{"kp_speed": 812}``), so the ``before`` of a result is
exactly what undo writes back.
"""

from __future__ import annotations

from collections.abc import Mapping

from servostudio.drive.access import Drive
from servostudio.drive.profiles.procedures import PHASING_RESULTS, ProcedureDescription
from servostudio.services.procedures.run import Values, read_values


def before_values(drive: Drive, description: ProcedureDescription) -> Values:
    return read_values(drive, [*description.results, *description.limits])


def shape(
    drive: Drive, name: str, description: ProcedureDescription, before: Mapping[str, object]
) -> dict[str, object]:
    """The result of a procedure that ended with status 5."""
    after = before_values(drive, description)
    if name == "auto_phasing" or (set(description.results) <= set(PHASING_RESULTS) and description.results):
        return _phasing(description, before, after)
    result: dict[str, object] = {"status": "done"}
    if name == "auto_tuning":
        result["identified"] = identified_plant(drive)
    gains = [item for item in description.results]
    if gains:
        result["gains"] = _pair(gains, before, after)
    if description.limits:
        result["limits"] = _pair(list(description.limits), before, after)
    return result


def aborted(
    description: ProcedureDescription, before: Mapping[str, object], now: Mapping[str, object]
) -> dict[str, object]:
    """An aborted run: what the objects were and are again."""
    result: dict[str, object] = {"status": "aborted"}
    if description.results:
        key = "gains" if not set(description.results) <= set(PHASING_RESULTS) else "values"
        result[key] = _pair(list(description.results), before, now)
    if description.limits:
        result["limits"] = _pair(list(description.limits), before, now)
    return result


def identified_plant(drive: Drive) -> dict[str, object]:
    """The identified plant the drive published (0x3428), and the inertia ratio to the motor's own (motor data)."""
    procedures = drive.profile.procedures
    values = read_values(drive, list(procedures.identified.values()))
    plant: dict[str, object] = {key: _number(values.get(name)) for key, name in procedures.identified.items()}
    if procedures.identified_per_ampere:
        return _per_ampere(plant)
    plant["inertia_ratio"] = _ratio(drive, plant.get("inertia_kgm2"))
    return plant


#: physical result keys → their names when the drive identifies per N·m/A of torque constant
PER_AMPERE_KEYS = {
    "inertia_kgm2": "inertia_as2_per_rad",
    "viscous_friction_nms_per_rad": "viscous_friction_as_per_rad",
    "coulomb_friction_nm": "coulomb_friction_a",
    "load_torque_nm": "load_torque_a",
}


def _per_ampere(plant: dict[str, object]) -> dict[str, object]:
    """A drive without a torque constant identifies in amperes of motor current: the physical keys stay unknown
    (null) rather than mislabelled, and the current-based values come beside them under ``per_ampere``."""
    shown: dict[str, object] = {key: None if key in PER_AMPERE_KEYS else value for key, value in plant.items()}
    shown["inertia_ratio"] = None
    shown["per_ampere"] = {named: plant.get(key) for key, named in PER_AMPERE_KEYS.items()}
    return shown


def _ratio(drive: Drive, inertia: object) -> float | None:
    """Total inertia / motor inertia (motor data); None when either is unknown or 0."""
    name = drive.profile.procedures.motor_inertia
    if name is None or not isinstance(inertia, float) or not drive.profile.has(name):
        return None
    motor = float(drive.read(name).physical)
    return round(inertia / motor, 3) if motor > 0 else None


def _phasing(
    description: ProcedureDescription, before: Mapping[str, object], after: Mapping[str, object]
) -> dict[str, object]:
    shown = [name for name in description.results if name in after]
    return {
        "status": "done",
        **{name: after[name] for name in shown},
        "before": {name: before.get(name) for name in shown},
    }


def _pair(names: list[str], before: Mapping[str, object], after: Mapping[str, object]) -> dict[str, object]:
    return {
        "before": {name: before[name] for name in names if name in before},
        "after": {name: after[name] for name in names if name in after},
    }


def _number(value: object) -> float | None:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return None
    return float(value)
