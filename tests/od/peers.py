"""The readers the loader is compared with in the corpus tests: python ``canopen.import_od`` entry by entry, and
lely's dcf-tools (the reference of CiA 306 the loader follows) where canopen follows a convention of its own."""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import canopen
import dcf
from canopen.objectdictionary import ODVariable
from dcf.lint import lint

from servostudio.od import Variable
from servostudio.od.ini import read_ini

NODE = 5


def dcfchk_verdict(path: Path) -> str:
    """What ``dcfchk -n NODE`` says of the file, in-process (no interpreter per file): "accepts" or "refuses"."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # dcfchk's reasons; the verdict is what counts here
        try:
            configuration = dcf.parse_file(str(path))
            if not lint(configuration):
                return "refuses"
            dcf.Device(configuration, {"NODEID": NODE})
        except (ValueError, KeyError, TypeError):  # dcf-tools stops on what it cannot read: that is its refusal
            return "refuses"
    return "accepts"


def canopen_copy(path: Path, tmp_path: Path) -> Path:
    """The file as canopen 2.4 can read it: without empty [DeviceInfo] numbers (it stops on them)."""
    text = re.sub(
        r"^(VendorNumber|ProductNumber|RevisionNumber)=\s*$\n", "", path.read_text(encoding="latin-1"), flags=re.M
    )
    copy = tmp_path / path.name
    copy.write_text(text, encoding="latin-1")
    return copy


def compact_indices(path: Path) -> set[int]:
    """The objects the file writes with CompactSubObj."""
    ini = read_ini(path)
    return {int(section.name, 16) for section in ini if len(section.name) == 4 and section.get("CompactSubObj")}


def canopen_entry(theirs: canopen.ObjectDictionary, variable: Variable) -> ODVariable:
    entry = theirs[variable.index]
    return entry if isinstance(entry, ODVariable) else entry[variable.subindex]


def canopen_view(entry: ODVariable) -> tuple:
    return (entry.name, entry.data_type, entry.access_type, entry.pdo_mappable, entry.min, entry.max)


def our_view(variable: Variable) -> tuple:
    access = variable.access.value
    return (variable.name, int(variable.data_type), access, variable.pdo_mappable, variable.low, variable.high)


def canopen_configured(entry: ODVariable) -> object:
    return entry.value if getattr(entry, "value_raw", None) not in (None, "") else None


def dcf_tools_view(entry: object) -> tuple:
    """An entry as dcf-tools reads it: name, access, type, PDO flag, limits and (configured, else default) value."""
    limits = [getattr(entry, key, None) for key in ("low_limit", "high_limit")]
    low, high = (limit.parse({"NODEID": NODE}) if limit is not None else None for limit in limits)
    names = (entry.name, entry.access_type.name, entry.data_type.index, entry.pdo_mapping)  # type: ignore[attr-defined]
    return (*names, low, high, entry.parse_value())  # type: ignore[attr-defined]


def our_dcf_tools_view(variable: Variable) -> tuple:
    value = variable.parameter_value_for(NODE)
    if value is None:
        value = variable.default_for(NODE)
    if value is None:  # neither configured nor a default: dcf-tools gives the type's empty value
        value = "" if variable.data_type.is_text else b"" if variable.data_type.is_binary else 0
    names = (variable.name, variable.access.value, int(variable.data_type), variable.pdo_mappable)
    return (*names, variable.low, variable.high, as_dcf_tools_value(variable, value))


def as_dcf_tools_value(variable: Variable, value: object) -> object:
    """dcf-tools keeps TIME values as (days, ms)."""
    if variable.data_type.is_time and isinstance(value, int):
        return (value >> 32, value & 0xFFFFFFFF)
    return value
