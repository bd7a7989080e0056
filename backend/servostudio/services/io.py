"""The I/O configuration of one drive (docs/io.md): what each logic input and output does and its polarity, the
analog scaling, encoder emulation and CANopen I/O extension, the live state, and the fail-safe check of the limit
switches — read through the device profile's I/O description (``drive/profiles/io.py``), never raw indices.

A change is checked whole before anything is written: every input, output and setting is resolved and range-checked,
a function given to two inputs is refused, and only then the writes go as one batch through the drive's write gate,
the motion guard, which judges the input functions, polarity and dedicated-function mask as motion objects (an
input may become ENABLE or a limit switch): on an enabled axis they need the caller to be its armed controller.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field

from servostudio.drive.access import DEFAULT_WAIT, Drive
from servostudio.drive.profiles.io import Function, IoDescription, LogicInput, Output, Routing, Setting
from servostudio.drive.sdo import SdoAbortError, settle
from servostudio.errors import Conflict, InvalidInput, NotFound
from servostudio.od import Variable

Key = tuple[int, int]
NONE = ("none", "general")  # the "no function" keys of a POINTER and a DEDICATED device
LISTED = 8  # a refusal lists the allowed functions up to this many


class NoIoDescription(NotFound):
    """The device has no I/O description in its profile."""


class IoChangeRefused(InvalidInput):
    """A change with any problem: nothing was written."""


class NotSimulated(Conflict):
    """The test bench's inputs exist only on a simulated drive."""


@dataclass(frozen=True)
class InputChange:
    name: str
    function: str | None = None
    inverted: bool | None = None


@dataclass(frozen=True)
class OutputChange:
    name: str
    function: str | None = None
    inverted: bool | None = None


@dataclass(frozen=True)
class IoChange:
    inputs: Sequence[InputChange] = ()
    outputs: Sequence[OutputChange] = ()
    settings: Mapping[str, object] = field(default_factory=dict)


def description(drive: Drive) -> IoDescription:
    found = drive.profile.io
    if found is None:
        raise NoIoDescription(f"node {drive.node}: no I/O description for device '{drive.profile.device}'")
    return found


# -- reading ---------------------------------------------------------------------------------------------------


class Values:
    """The objects of one read, all queued at once; an object the drive refuses has no value."""

    def __init__(self, drive: Drive, keys: Iterable[Key]) -> None:
        variables = [drive.variable(key) for key in dict.fromkeys(keys) if _known(drive, key)]
        readable = [variable for variable in variables if variable.access.readable]
        self.variables = {variable.key: variable for variable in variables}
        self.values: dict[Key, object] = {}
        outcomes = drive.submit_read_all(readable).future.result(DEFAULT_WAIT) if readable else []
        for variable, outcome in zip(readable, outcomes, strict=True):
            if isinstance(outcome, Exception) and not isinstance(outcome, (SdoAbortError, ValueError)):
                raise outcome
            if not isinstance(outcome, Exception):
                self.values[variable.key] = outcome.raw

    def int(self, key: Key | None) -> int | None:
        value = self.values.get(key) if key is not None else None
        return int(value) if isinstance(value, int) else None


def _known(drive: Drive, key: Key) -> bool:
    return drive.dictionary is not None and key in drive.dictionary


def _address(drive: Drive, name: str | None) -> Key | None:
    return drive.profile.address(name) if name and drive.profile.has(name) else None


def _keys(drive: Drive, io: IoDescription) -> list[Key]:
    names = [io.input_polarity, io.input_mask, io.output_polarity, io.output_functions_object, *_STATE_NAMES]
    names += [item.destination for item in io.inputs] + [item.source for item in io.outputs]
    keys = [key for key in (_address(drive, name) for name in names) if key is not None]
    return keys + [setting.address for group in io.groups for setting in (*group.settings, *group.live)]


def read(drive: Drive, simulated: bool = False) -> dict[str, object]:
    """The whole configuration, the live state and the fail-safe findings (``simulated``: the test bench's inputs
    too)."""
    io = description(drive)
    values = Values(drive, _keys(drive, io))
    inputs = [_input_row(drive, io, values, item) for item in io.inputs]
    outputs = [_output_row(drive, io, values, item) for item in io.outputs]
    return {
        "node": drive.node,
        "device": drive.profile.device,
        "routing": io.routing.value,
        "note": io.note,
        "functions": [_function_row(function) for function in io.functions],
        "output_functions": [_function_row(function) for function in io.output_functions],
        "inputs": inputs,
        "outputs": outputs,
        "groups": [_group_row(values, group.key, group.title, group.settings, group.live) for group in io.groups],
        "state": _state(drive, values),
        "findings": fail_safe(io, inputs),
        "simulated": _sim_inputs(drive, io) if simulated else None,
    }


def _function_row(function: Function) -> dict[str, object]:
    return {
        "key": function.key,
        "label": function.label,
        "limit": function.limit,
        "condition_bit": function.condition_bit,
    }


def _input_row(drive: Drive, io: IoDescription, values: Values, item: LogicInput) -> dict[str, object]:
    image = values.int(_address(drive, "digital_inputs"))
    function, pointer = _input_function(drive, io, values, item)
    return {
        "name": item.name,
        "bit": item.bit,
        "physical": item.physical,
        "function": function,
        "pointer": pointer,
        "allowed": _allowed(io, item),
        "inverted": _bit(values.int(_address(drive, io.input_polarity)), item.polarity_bit),
        "active": _bit(image, item.bit),
    }


def _allowed(io: IoDescription, item: LogicInput) -> list[str]:
    if io.routing is Routing.DEDICATED:
        return ["general", item.dedicated or "general"]
    return [function.key for function in io.functions]


def _input_function(drive: Drive, io: IoDescription, values: Values, item: LogicInput) -> tuple[str, int | None]:
    """The input's function key (``other`` for a pointer no function names) and, on a POINTER device, its
    pointer."""
    if io.routing is Routing.DEDICATED:
        dedicated = _bit(values.int(_address(drive, io.input_mask)), item.mask_bit)
        return (item.dedicated or "general") if dedicated else "general", None
    value = values.int(_address(drive, item.destination))
    known = io.function_of_pointer(value) if value is not None else None
    return (known.key if known else "other"), value


def _output_row(drive: Drive, io: IoDescription, values: Values, item: Output) -> dict[str, object]:
    image = values.int(_address(drive, "digital_outputs"))
    function, pointer = _output_function(drive, io, values, item)
    return {
        "name": item.name,
        "bit": item.bit,
        "physical": item.physical,
        "function": function,
        "pointer": pointer,
        "inverted": _bit(values.int(_address(drive, io.output_polarity)), item.polarity_bit),
        "active": _bit(image, item.bit),
    }


def _output_function(drive: Drive, io: IoDescription, values: Values, item: Output) -> tuple[str, int | None]:
    if item.function_bits is not None:
        word = values.int(_address(drive, io.output_functions_object)) or 0
        chosen = [key for key, bit in item.function_bits.items() if word >> bit & 1]
        return (chosen[0] if chosen else "general"), None
    value = values.int(_address(drive, item.source))
    known = next((function for function in io.output_functions if function.value == value), None)
    return (known.key if known else "other"), value


def _bit(word: int | None, bit: int | None) -> bool | None:
    return None if word is None or bit is None else bool(word >> bit & 1)


def _group_row(
    values: Values, key: str, title: str, settings: Sequence[Setting], live: Sequence[Setting]
) -> dict[str, object]:
    return {
        "key": key,
        "title": title,
        "settings": [_setting_row(values, setting) for setting in settings if setting.address in values.variables],
        "live": [_setting_row(values, setting) for setting in live if setting.address in values.variables],
    }


def _setting_row(values: Values, setting: Setting) -> dict[str, object]:
    variable = values.variables[setting.address]
    index, sub = setting.address
    return {
        "key": setting.key,
        "label": setting.label,
        "address": f"0x{index:04X},{sub}",
        "value": values.int(setting.address),
        "low": variable.low if isinstance(variable.low, int) else None,
        "high": variable.high if isinstance(variable.high, int) else None,
        "pointer": setting.is_pointer,
        "writable": variable.access.writable,
    }


# -- live state ------------------------------------------------------------------------------------------------

_STATE_NAMES = ("digital_inputs", "digital_outputs", "physical_inputs_16")
#: 0x60FD bits 0-3: what the drive acts on now
_FUNCTION_BITS = {"negative_limit": 0, "positive_limit": 1, "home": 2, "inhibit": 3}


def _state(drive: Drive, values: Values) -> dict[str, object]:
    image = values.int(_address(drive, "digital_inputs"))
    return {
        "inputs": image,
        "outputs": values.int(_address(drive, "digital_outputs")),
        **{name: _bit(image, bit) for name, bit in _FUNCTION_BITS.items()},
    }


def state(drive: Drive, simulated: bool = False) -> dict[str, object]:
    """The live part alone (cheap enough to poll): the input and output images, each input and output's level,
    what the drive acts on, the analog values and, on a simulated drive, the test bench's inputs."""
    io = description(drive)
    live = [setting for group in io.groups for setting in group.live]
    keys = [key for key in (_address(drive, name) for name in _STATE_NAMES) if key is not None]
    values = Values(drive, [*keys, *(setting.address for setting in live)])
    inputs, outputs = values.int(_address(drive, "digital_inputs")), values.int(_address(drive, "digital_outputs"))
    return {
        **_state(drive, values),
        "input_levels": {item.name: _bit(inputs, item.bit) for item in io.inputs},
        "output_levels": {item.name: _bit(outputs, item.bit) for item in io.outputs},
        "analog": {setting.key: values.int(setting.address) for setting in live},
        "simulated": _sim_inputs(drive, io) if simulated else None,
    }


# -- the fail-safe check ---------------------------------------------------------------------------------------


def fail_safe(io: IoDescription, inputs: Sequence[Mapping[str, object]]) -> list[dict[str, str]]:
    """What makes the limit switches unsafe, and why (manual, XtrapulsPac §2.4.7: a limit switch "must be active
    when disconnected from +24 V"); also the notes the device's I/O needs (no polarity, nothing configurable)."""
    if io.routing is Routing.FIXED:
        return [_finding("note", "inputs", io.note)]
    limits = {function.key: function.limit for function in io.functions if function.limit}
    findings = [finding for row in inputs for finding in _input_findings(io, row, limits)]
    findings += _missing_limits(io, inputs, limits)
    if io.routing is Routing.DEDICATED:
        findings.append(_finding("note", "polarity", io.note))
    return findings


def _finding(severity: str, subject: str, text: str) -> dict[str, str]:
    return {"severity": severity, "subject": subject, "text": text}


def _direction(limit: int) -> str:
    return "positive" if limit > 0 else "negative"


def _input_findings(io: IoDescription, row: Mapping[str, object], limits: Mapping[str, int]) -> list[dict[str, str]]:
    name, function = str(row["name"]), str(row["function"])
    if io.routing is Routing.DEDICATED:
        return _freed_limit(row, limits)
    limit = limits.get(function)
    if not limit:
        return []
    found = []
    if row["inverted"] is False:
        found.append(_finding("unsafe", name, _NOT_FAIL_SAFE.format(name=name, direction=_direction(limit))))
    if not row["physical"]:
        found.append(_finding("warning", name, _VIRTUAL_LIMIT.format(name=name)))
    if row["active"]:
        found.append(_finding("note", name, _ACTIVE_NOW.format(name=name, direction=_direction(limit))))
    return found


def _freed_limit(row: Mapping[str, object], limits: Mapping[str, int]) -> list[dict[str, str]]:
    allowed = row["allowed"]
    dedicated = allowed[-1] if isinstance(allowed, list) else None
    limit = limits.get(str(dedicated))
    if not limit or row["function"] == dedicated:
        return []
    return [_finding("unsafe", str(row["name"]), _FREED.format(name=row["name"], direction=_direction(limit)))]


def _missing_limits(
    io: IoDescription, inputs: Sequence[Mapping[str, object]], limits: Mapping[str, int]
) -> list[dict[str, str]]:
    if io.routing is not Routing.POINTER:
        return []
    used = {row["function"] for row in inputs}
    missing = [key for key in limits if key not in used]
    return [_finding("warning", key, _NO_LIMIT.format(direction=_direction(limits[key]))) for key in missing]


_NOT_FAIL_SAFE = (
    "{name} is the {direction} limit switch with normal polarity: it stops the axis only while 24 V reaches it, so "
    "a broken wire, a lost 24 V supply or a switch that fails open lets the axis run through. Wire a normally "
    "closed switch and invert {name}, so that the limit is active when disconnected from +24 V."
)
_VIRTUAL_LIMIT = "{name} is a virtual input: no switch is wired to it, only an object or a linked output sets it."
_ACTIVE_NOW = (
    "{name} ({direction} limit switch) is active now: the drive refuses motion in the {direction} direction. Unless "
    "the axis stands on its switch, the switch's wire or its 24 V is missing."
)
_FREED = "{name} is freed for general use: the drive no longer stops at the {direction} limit switch wired to it."
_NO_LIMIT = (
    "No input is the {direction} limit switch: nothing but the software position limits stops the axis in the "
    "{direction} direction."
)


# -- changing --------------------------------------------------------------------------------------------------


@dataclass
class _Plan:
    """The writes of a change, in the order they go: functions removed, polarity and mask, functions given, then
    outputs and settings — an input never gets a new function under the polarity it is about to lose."""

    cleared: list[tuple[Variable, int]] = field(default_factory=list)
    words: list[tuple[Variable, int]] = field(default_factory=list)
    given: list[tuple[Variable, int]] = field(default_factory=list)
    rest: list[tuple[Variable, object]] = field(default_factory=list)
    problems: list[str] = field(default_factory=list)

    def writes(self) -> list[tuple[Variable, object]]:
        return [*self.cleared, *self.words, *self.given, *self.rest]


def apply(drive: Drive, change: IoChange, simulated: bool = False) -> dict[str, object]:
    """Check the whole change, then write it as one batch through the motion guard; the configuration after."""
    io = description(drive)
    values = Values(drive, _keys(drive, io))
    plan = _Plan()
    _plan_inputs(drive, io, values, change.inputs, plan)
    _plan_outputs(drive, io, values, change.outputs, plan)
    _plan_settings(drive, io, change.settings, plan)
    if plan.problems:
        raise IoChangeRefused("; ".join(plan.problems) + "; nothing was written")
    writes = plan.writes()
    if writes:
        _write(drive, writes)
    return {**read(drive, simulated), "written": [f"0x{var.index:04X},{var.subindex}" for var, _ in writes]}


def _write(drive: Drive, writes: Sequence[tuple[Variable, object]]) -> None:
    for variable, value in writes:  # the dictionary's range check of every value before the first frame
        try:
            drive.prepare_write(variable, value)
        except InvalidInput as error:
            raise IoChangeRefused(f"{error}; nothing was written") from None
    outcomes = drive.submit_write_all(list(writes)).future.result(DEFAULT_WAIT)
    failed = [outcome for outcome in outcomes if isinstance(outcome, Exception)]
    if failed:
        raise failed[0]


def _plan_inputs(drive: Drive, io: IoDescription, values: Values, changes: Sequence[InputChange], plan: _Plan) -> None:
    functions = {row.name: _input_function(drive, io, values, row)[0] for row in io.inputs}
    polarity = _word(drive, values, io.input_polarity)
    mask = _word(drive, values, io.input_mask)
    for change in changes:
        item = io.input(change.name)
        if item is None:
            plan.problems.append(f"no input {change.name!r} (inputs: {', '.join(row.name for row in io.inputs)})")
            continue
        if change.function is not None:
            mask = _plan_function(drive, io, item, change.function, functions, mask, plan)
        if change.inverted is not None:
            polarity = _flip(polarity, item.polarity_bit, change.inverted, f"{item.name} has no polarity", plan)
    _duplicates(functions, plan)
    _plan_word(drive, io.input_polarity, values, polarity, plan)
    _plan_word(drive, io.input_mask, values, mask, plan)


def _word(drive: Drive, values: Values, name: str | None) -> int | None:
    return values.int(_address(drive, name))


def _flip(word: int | None, bit: int | None, on: bool, refusal: str, plan: _Plan) -> int | None:
    if word is None or bit is None:
        plan.problems.append(f"{refusal} on this device")
        return word
    return word | 1 << bit if on else word & ~(1 << bit)


def _plan_function(
    drive: Drive,
    io: IoDescription,
    item: LogicInput,
    key: str,
    functions: dict[str, str],
    mask: int | None,
    plan: _Plan,
) -> int | None:
    allowed = _allowed(io, item)
    if key not in allowed:
        known = ", ".join(allowed) if len(allowed) <= LISTED else "the keys of `functions`"
        plan.problems.append(f"{item.name}: function {key!r} is not one of {known}")
        return mask
    functions[item.name] = key
    if io.routing is Routing.DEDICATED:
        return _flip(mask, item.mask_bit, key != "general", f"{item.name} has no dedicated function", plan)
    function = io.function(key)
    target = drive.variable(drive.profile.address(item.destination or ""))
    (plan.cleared if key == "none" else plan.given).append((target, function.value if function else 0))
    return mask


def _duplicates(functions: Mapping[str, str], plan: _Plan) -> None:
    """Two inputs copied into one bit: the one that changed last would decide, so the drive would act on neither
    reliably."""
    holders: dict[str, list[str]] = {}
    for name, key in functions.items():
        if key not in NONE and key != "other":
            holders.setdefault(key, []).append(name)
    for key, names in holders.items():
        if len(names) > 1:
            plan.problems.append(f"{' and '.join(names)} would both be '{key}': give each function to one input")


def _plan_word(drive: Drive, name: str | None, values: Values, word: int | None, plan: _Plan) -> None:
    key = _address(drive, name)
    if key is not None and word is not None and word != values.int(key):
        plan.words.append((drive.variable(key), word))


def _plan_outputs(
    drive: Drive, io: IoDescription, values: Values, changes: Sequence[OutputChange], plan: _Plan
) -> None:
    polarity = _word(drive, values, io.output_polarity)
    specific = _word(drive, values, io.output_functions_object)
    for change in changes:
        item = io.output(change.name)
        if item is None:
            plan.problems.append(f"no output {change.name!r} (outputs: {', '.join(row.name for row in io.outputs)})")
            continue
        if change.function is not None:
            specific = _plan_output_function(drive, io, item, change.function, specific, plan)
        if change.inverted is not None:
            polarity = _flip(polarity, item.polarity_bit, change.inverted, f"{item.name} has no polarity", plan)
    _plan_word(drive, io.output_polarity, values, polarity, plan)
    _plan_word(drive, io.output_functions_object, values, specific, plan)


def _plan_output_function(
    drive: Drive, io: IoDescription, item: Output, key: str, specific: int | None, plan: _Plan
) -> int | None:
    function = io.output_function(key)
    if function is None:
        known = ", ".join(row.key for row in io.output_functions)
        plan.problems.append(f"{item.name}: function {key!r} is not one of {known}")
        return specific
    if item.function_bits is not None:
        if specific is None:
            return specific
        for bit in item.function_bits.values():
            specific &= ~(1 << bit)
        return specific | (1 << item.function_bits[key] if key in item.function_bits else 0)
    plan.rest.append((drive.variable(drive.profile.address(item.source or "")), function.value))
    return specific


def _plan_settings(drive: Drive, io: IoDescription, settings: Mapping[str, object], plan: _Plan) -> None:
    for key, value in settings.items():
        setting = io.setting(key)
        if setting is None or not _known(drive, setting.address):
            plan.problems.append(f"no setting {key!r} on this device")
            continue
        try:
            variable, raw, _ = drive.prepare_write(setting.address, value)
        except InvalidInput as error:
            plan.problems.append(f"{setting.label} ({key}): {error}")
            continue
        if setting.is_pointer and not _points_somewhere(drive, raw):
            plan.problems.append(f"{setting.label} ({key}): {value!r} points to no object of this drive")
            continue
        plan.rest.append((variable, raw))


def _points_somewhere(drive: Drive, raw: object) -> bool:
    """A pointer ``index << 16 | sub << 8 | bit-or-size`` names an object of the dictionary (0 = none)."""
    return isinstance(raw, int) and (raw == 0 or _known(drive, (raw >> 16 & 0xFFFF, raw >> 8 & 0xFF)))


# -- the simulated drive's test bench --------------------------------------------------------------------------


def _sim_inputs(drive: Drive, io: IoDescription) -> dict[str, object] | None:
    key = _address(drive, "sim_physical_inputs")
    if key is None or not io.sim_inputs:
        return None
    data = settle(drive.engine.upload(drive.node, key[0], key[1]), DEFAULT_WAIT)
    return {"names": list(io.sim_inputs), "meaning": io.sim_meaning, "value": int.from_bytes(data[:2], "little")}


def set_sim_inputs(drive: Drive, value: int, simulated: bool) -> dict[str, object]:
    """The test bench's inputs of a simulated drive (0x5F00, simulator only: a raw write the guard still judges)."""
    io = description(drive)
    key = _address(drive, "sim_physical_inputs")
    if not simulated or key is None or not io.sim_inputs:
        raise NotSimulated(f"node {drive.node}: test bench inputs exist only on a simulated XtrapulsPac or CD1-k")
    if not 0 <= value < 1 << len(io.sim_inputs):
        raise InvalidInput(f"test bench inputs {value}: {len(io.sim_inputs)} bits ({', '.join(io.sim_inputs)})")
    drive.write_raw_bytes(key[0], key[1], value.to_bytes(2, "little"))
    return state(drive, simulated)
