"""DCF export and import of one axis (CiA 306 Device Configuration File).

A DCF is the device's EDS plus what commissioning decided: a ``[DeviceComissioning]`` section (node ID, bit rate,
node name; CiA 306 spells it with one 'm'; no LSS serial number, which the project does not know) and a
``ParameterValue=`` line in the section of every object whose value the project sets. Copying the EDS line by line
keeps everything a DCF reader expects (comments, key order) intact.

Import is the way back: the DCF's configured values (``ParameterValue``, ``[xxxxValue]``) become the axis's offline
values, checked like any offline edit; those the project cannot hold (not saved in a drive file, read-only) are
listed, not dropped silently.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from servostudio.od import ObjectDictionary, ObjectKind, Variable
from servostudio.od.eds_values import float_bit_pattern, time_text
from servostudio.services.projects.axisvalues import AxisValues
from servostudio.services.projects.errors import ParameterRefused
from servostudio.services.projects.model import Axis, Project
from servostudio.services.projects.parameter_values import Value

_SECTION = re.compile(r"^\s*\[([^\]]+)\]\s*$")
_OBJECT_SECTION = re.compile(r"^([0-9A-Fa-f]{4})(?:sub([0-9A-Fa-f]{1,2}))?$")
_PARAMETER_VALUE = re.compile(r"^\s*ParameterValue\s*=", re.IGNORECASE)


def export_dcf(eds_text: str, project: Project, axis: Axis, values: AxisValues) -> str:
    """The DCF text for ``axis``: the EDS with ``ParameterValue`` for each value set in the project files."""
    newline = "\r\n" if "\r\n" in eds_text else "\n"
    lines = eds_text.replace("\r\n", "\n").split("\n")
    while lines and not lines[-1].strip():
        lines.pop()
    out: list[str] = []
    pending: str | None = None
    for line in lines:
        match = _SECTION.match(line)
        if match:
            _close_section(out, pending)
            pending = _parameter_line(values, match.group(1))
        elif pending is not None and _PARAMETER_VALUE.match(line):
            continue
        out.append(line)
    _close_section(out, pending)
    out.extend(["", "[DeviceComissioning]", *_commissioning(project, axis)])
    return newline.join(out) + newline


def _close_section(out: list[str], pending: str | None) -> None:
    """Put the ParameterValue line after the section's last key (before the blank lines that separate sections)."""
    if pending is None:
        return
    blanks = 0
    while out and not out[-1].strip():
        out.pop()
        blanks += 1
    out.append(pending)
    out.extend([""] * blanks)


def _parameter_line(values: AxisValues, section: str) -> str | None:
    match = _OBJECT_SECTION.match(section)
    if not match:
        return None
    index, sub = int(match.group(1), 16), int(match.group(2) or "0", 16)
    variable = values.dictionary.get(index, sub)
    if variable is None or (match.group(2) is None and values.dictionary.object(index).kind is not ObjectKind.VAR):
        return None
    value = values.explicit(variable)
    return None if value is None else f"ParameterValue={format_value(variable, value)}"


@dataclass(frozen=True)
class ConfiguredValues:
    """What a DCF configures for an axis: the values the project takes, and why the others stay out."""

    values: list[tuple[Variable, Value]]
    skipped: list[str]


def configured_values(dcf: ObjectDictionary, values: AxisValues) -> ConfiguredValues:
    """The DCF's configured values for the axis's dictionary and node (``$NODEID`` resolved for the axis)."""
    _check_identity(dcf, values.dictionary)
    taken: list[tuple[Variable, Value]] = []
    skipped: list[str] = []
    for entry in dcf.variables():
        value = entry.parameter_value_for(values.node_id)
        if value is None:
            continue
        variable = values.dictionary.get(entry.index, entry.subindex)
        if variable is None:
            skipped.append(f"{entry.label} is not in the {values.dictionary.device} dictionary")
        elif reason := values.editable_reason(variable):
            skipped.append(reason)
        else:
            taken.append((variable, value))
    return ConfiguredValues(taken, skipped)


def _check_identity(dcf: ObjectDictionary, dictionary: ObjectDictionary) -> None:
    """A DCF configures one kind of device: its identity must be the axis's (values of another drive's objects
    would land on objects of the same address but another meaning)."""
    if (dcf.vendor_id, dcf.product_code) != (dictionary.vendor_id, dictionary.product_code):
        raise ParameterRefused(
            f"{dcf.source.name} describes vendor 0x{dcf.vendor_id:X}, product 0x{dcf.product_code:X}; the axis is "
            f"a {dictionary.device} (vendor 0x{dictionary.vendor_id:X}, product 0x{dictionary.product_code:X})"
        )


def format_value(variable: Variable, value: Value) -> str:
    """EDS spelling: integers hex for unsigned types and decimal for signed ones, REAL as its bit pattern, TIME as
    "days ms"."""
    data_type = variable.data_type
    if data_type.is_float:
        return float_bit_pattern(data_type, float(value))
    if data_type.is_time and isinstance(value, int):
        return time_text(value)
    if isinstance(value, bytes):
        return value.hex().upper()
    if isinstance(value, int) and not data_type.is_signed:
        return f"0x{value:X}"
    return str(value)


def _commissioning(project: Project, axis: Axis) -> list[str]:
    bus = project.bus(axis.bus)
    lines = [f"NodeID={axis.node_id}", f"NodeName={axis.name}"]
    if bus is not None and bus.bitrate:
        lines.append(f"Baudrate={bus.bitrate // 1000}")
    lines += ["NetNumber=1", f"NetworkName={project.name}", "CANopenManager=0"]
    return lines
