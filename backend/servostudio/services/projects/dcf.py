"""DCF export of one axis (CiA 306 Device Configuration File).

A DCF is the device's EDS plus what commissioning decided: a ``[DeviceComissioning]`` section (node ID, bit rate,
node name; CiA 306 spells it with one 'm'; no LSS serial number, which the project does not know) and a
``ParameterValue=`` line in the section of every object whose value the project sets. Copying the EDS line by line
keeps everything a DCF reader expects (comments, key order) intact.
"""

from __future__ import annotations

import re

from servostudio.od import ObjectKind, Variable
from servostudio.od.eds_values import float_bit_pattern
from servostudio.services.projects.axisvalues import AxisValues
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


def format_value(variable: Variable, value: Value) -> str:
    """EDS spelling: integers hex for unsigned types and decimal for signed ones, REAL as its bit pattern."""
    data_type = variable.data_type
    if data_type.is_float:
        return float_bit_pattern(data_type, float(value))
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
