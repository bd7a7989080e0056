"""A procedure's options as a request gives them (``{"bandwidth": 75, "filter": "anti-resonance"}``) → the writes
the drive gets, every one checked before anything is sent.

The codes are the profile's (``OptionCodes``); options that share an object add their codes (the CD1-k's bandwidth
and filter are one object). An option a drive does not have, or a value it does not know, is refused with the
values it accepts.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from servostudio.drive.access import Drive
from servostudio.drive.profiles.procedures import ProcedureDescription
from servostudio.errors import InvalidInput
from servostudio.od.model import Variable

#: what an option is when the request leaves it out (auto-tuning: every run fully specified, so it is repeatable)
DEFAULTS: dict[str, dict[str, str]] = {
    "auto_tuning": {"bandwidth": "75", "filter": "standard", "speed_filter": "auto", "mode": "min-following-error"},
}
#: the options the API knows for each procedure, whether or not a drive has them
KNOWN: dict[str, tuple[str, ...]] = {
    "auto_tuning": ("bandwidth", "filter", "speed_filter", "mode"),
    "current_loop": ("inductance_mh", "regulator"),
}


class BadOptions(InvalidInput):
    """Options refused before anything was written."""


Write = tuple[Variable, object]


def option_writes(drive: Drive, name: str, description: ProcedureDescription, given: Mapping[str, Any]) -> list[Write]:
    """The writes the options make, value options (a physical value) first; refuses before anything is sent."""
    chosen = _chosen(drive, name, description, given)
    writes = [
        _value_write(drive, description.values[key], value)
        for key, value in chosen.items()
        if key in description.values
    ]
    codes: dict[str, int] = {}
    for key, value in chosen.items():
        if key in description.options:
            option = description.options[key]
            codes[option.object] = codes.get(option.object, 0) + _code(drive, key, value, option.codes)
    for object_name, code in codes.items():
        variable, raw, _ = drive.prepare_write(object_name, code)
        writes.append((variable, raw))
    return writes


def shown(name: str, given: Mapping[str, Any]) -> dict[str, object]:
    """The options a run used, defaults filled in (for the result); a choice spelled as its label whether the
    request gave 75 (REST) or "75" (CLI), so saved results compare alike."""
    defaults = DEFAULTS.get(name, {})
    chosen = {key: _text(value) if key in defaults else value for key, value in given.items() if value is not None}
    return {**defaults, **chosen}


def _chosen(drive: Drive, name: str, description: ProcedureDescription, given: Mapping[str, Any]) -> dict[str, Any]:
    known = KNOWN.get(name, ())
    unknown = sorted(set(given) - set(known))
    if unknown:
        accepted = ", ".join(known) or "none"
        raise BadOptions(f"{name}: unknown option {', '.join(unknown)} (it takes {accepted})")
    chosen = {**DEFAULTS.get(name, {}), **{key: value for key, value in given.items() if value is not None}}
    for key in chosen:
        if key not in description.options and key not in description.values:
            default = DEFAULTS.get(name, {}).get(key)
            if key in given and _text(given[key]) != default:
                raise BadOptions(f"node {drive.node}: the {drive.profile.device} has no {key} option for {name}")
    return {key: value for key, value in chosen.items() if key in description.options or key in description.values}


def _code(drive: Drive, key: str, value: Any, codes: Mapping[str, int]) -> int:
    text = _text(value)
    if text not in codes:
        raise BadOptions(f"node {drive.node}: {key} {text!r} is not one of {', '.join(codes)}")
    return codes[text]


def _value_write(drive: Drive, object_name: str, value: Any) -> Write:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or value <= 0:
        raise BadOptions(f"node {drive.node}: {object_name.replace('_', ' ')} {value!r} must be a positive number")
    variable, raw, _ = drive.prepare_write(object_name, value, physical=True)
    return variable, raw


def _text(value: Any) -> str:
    """50, 50.0 and "50" are the same choice; 0.5 stays "0.5"."""
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, float) and value.is_integer():
        return str(int(value))
    return str(value)
