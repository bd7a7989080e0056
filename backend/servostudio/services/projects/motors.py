"""The motor catalog (manual §2.4.2, L501-531, L1223-1228): one text file per motor, built-in and user entries.

A motor file is the TOML subset of ``tomlsubset``::

    [motor]
    reference = "..."          # unique; also the file name (<reference>.toml)
    description = "..."
    source = "..."             # where the data comes from (datasheet, measurement)

    [motor_data]               # object 0x6410 by sub-entry name (see MOTOR_DATA_SUBS), raw object units
    manufacturer = "..."
    pole_pairs = 4

    [objects]                  # further objects the motor sets, e.g. position and thermal sensor
    "0x3324,1" = -1

Built-in entries live in ``<repo>/motors`` (read-only); "Add new motor" writes to the user directory.
"""

from __future__ import annotations

import os
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

from servostudio.services.projects import tomlsubset
from servostudio.services.projects.errors import FileFormatError, ProjectExists, ProjectNotFound, ValidationError
from servostudio.services.projects.fsutil import atomic_write
from servostudio.services.projects.names import check_name, same_name

#: the repository's ``motors/`` folder; ``builtin_motors_dir()`` is what a process uses
BUILTIN_MOTORS_DIR = Path(__file__).resolve().parents[4] / "motors"


def builtin_motors_dir(environ: Mapping[str, str] = os.environ) -> Path:
    """The built-in catalog: ``SERVOSTUDIO_MOTORS_DIR``, else the repository's ``motors/`` (read when asked)."""
    return Path(environ.get("SERVOSTUDIO_MOTORS_DIR") or BUILTIN_MOTORS_DIR)


#: The motor data of a catalog entry, in the order of the sub-entries 1..25 of the XtrapulsPac's 0x6410 Motor Data
#: (manual L4894-5268), which is what Gem Drive Studio's catalog fills in.
MOTOR_DATA_FIELDS: tuple[str, ...] = (
    "manufacturer",
    "model",
    "code",
    "catalog_date",
    "modification_date",
    "motor_type",
    "max_speed",
    "rated_speed",
    "stall_current",
    "peak_current",
    "torque_constant",
    "inertia",
    "inductance",
    "pole_pairs",
    "phase_order",
    "sensor_offset",
    "temperature_probe",
    "temperature_warning",
    "temperature_error",
    "pole_pitch",
    "magnetization_current",
    "rotor_time_constant",
    "base_speed",
    "leakage_factor",
    "saturation_model",
)
_TEXT_FIELDS = {"manufacturer", "model", "code"}
_ADDRESS = re.compile(r"0x([0-9A-Fa-f]{4}),([0-9]{1,3})")
HEADER = "Servo Studio motor catalog entry: see docs/projects.md"


@dataclass(frozen=True)
class Motor:
    reference: str
    description: str = ""
    source: str = ""
    motor_data: dict[str, int | str] = field(default_factory=dict)
    objects: dict[tuple[int, int], int | float | str] = field(default_factory=dict)
    builtin: bool = False


def motor_to_text(motor: Motor) -> str:
    document: tomlsubset.Document = {
        ("motor",): tomlsubset.Table(
            values={
                key: value
                for key, value in (
                    ("reference", motor.reference),
                    ("description", motor.description),
                    ("source", motor.source),
                )
                if value
            }
        ),
        ("motor_data",): tomlsubset.Table(
            values={name: motor.motor_data[name] for name in MOTOR_DATA_FIELDS if name in motor.motor_data}
        ),
    }
    if motor.objects:
        document[("objects",)] = tomlsubset.Table(
            values={f"0x{index:04X},{sub}": value for (index, sub), value in sorted(motor.objects.items())}
        )
    return tomlsubset.dump(document, HEADER)


def motor_from_text(text: str, source: Path | str, builtin: bool = False) -> Motor:
    document = tomlsubset.parse(text, source)
    head = document.get(("motor",))
    if head is None:
        raise FileFormatError(source, 1, "the [motor] table is missing")
    for path, table in document.items():
        if path not in (("motor",), ("motor_data",), ("objects",)):
            raise FileFormatError(
                source,
                table.line,
                f"unknown table [{tomlsubset.format_path(path)}]; expected [motor], [motor_data], [objects]",
            )
    for key, line in head.lines.items():
        if key not in ("reference", "description", "source") or not isinstance(head.values[key], str):
            raise FileFormatError(
                source, line, f"[motor] key '{key}' must be one of reference, description, source, as a quoted string"
            )
    if "reference" not in head.values:
        raise FileFormatError(source, head.line, "[motor] needs a reference")
    data = document.get(("motor_data",), tomlsubset.Table())
    for key, value in data.values.items():
        _check_data_field(key, value, source, data.lines[key])
    objects: dict[tuple[int, int], int | float | str] = {}
    other = document.get(("objects",), tomlsubset.Table())
    for key, value in other.values.items():
        match = _ADDRESS.fullmatch(key)
        if not match or isinstance(value, bool):
            raise FileFormatError(
                source,
                other.lines[key],
                f'[objects] key {key!r} must look like "0x3324,1" and its value be a number or a string',
            )
        objects[(int(match[1], 16), int(match[2]))] = value
    checked = {name: value for name, value in data.values.items() if isinstance(value, int | str)}  # all, checked
    motor_data = {name: checked[name] for name in MOTOR_DATA_FIELDS if name in checked}
    return Motor(
        str(head.values["reference"]),
        str(head.values.get("description", "")),
        str(head.values.get("source", "")),
        motor_data,
        objects,
        builtin,
    )


def _check_data_field(key: str, value: object, source: Path | str, line: int) -> None:
    if key not in MOTOR_DATA_FIELDS:
        raise FileFormatError(source, line, f"unknown motor data '{key}' (known: {', '.join(MOTOR_DATA_FIELDS)})")
    wanted = str if key in _TEXT_FIELDS else int
    if type(value) is not wanted:
        raise FileFormatError(source, line, f"motor data '{key}' must be {'text' if wanted is str else 'an integer'}")


class MotorCatalog:
    """Built-in motors plus the user's; a user motor may not reuse a built-in reference."""

    def __init__(self, builtin_dir: Path = BUILTIN_MOTORS_DIR, user_dir: Path | None = None) -> None:
        self.builtin_dir = Path(builtin_dir)
        self.user_dir = Path(user_dir) if user_dir is not None else None

    def motors(self) -> list[Motor]:
        found: dict[str, Motor] = {}
        for directory, builtin in ((self.builtin_dir, True), (self.user_dir, False)):
            for path in _motor_files(directory):
                motor = _motor_file(path, builtin)
                found.setdefault(motor.reference.casefold(), motor)
        return sorted(found.values(), key=lambda motor: motor.reference.casefold())

    def get(self, reference: str) -> Motor:
        for motor in self.motors():
            if same_name(motor.reference, reference):
                return motor
        raise ProjectNotFound(f"no motor '{reference}' in the catalog")

    def add(self, motor: Motor, replace_existing: bool = False) -> Motor:
        """ "Add new motor": store a user entry; a built-in reference is never overwritten."""
        if self.user_dir is None:
            raise ValidationError("this motor catalog has no user directory")
        check_name(motor.reference, "motor")
        for key, value in motor.motor_data.items():
            _check_data_field(key, value, f"motor {motor.reference}", 0)
        for existing in self.motors():
            if same_name(existing.reference, motor.reference) and (existing.builtin or not replace_existing):
                raise ProjectExists(
                    f"motor '{existing.reference}' is already in the catalog"
                    + (" (built-in)" if existing.builtin else "")
                )
        self.user_dir.mkdir(parents=True, exist_ok=True)
        text = motor_to_text(motor)
        motor_from_text(text, f"motor {motor.reference}")
        atomic_write(self.user_dir / f"{motor.reference}.toml", text)
        return Motor(motor.reference, motor.description, motor.source, motor.motor_data, motor.objects, False)

    def remove(self, reference: str) -> None:
        motor = self.get(reference)
        if motor.builtin:
            raise ValidationError(f"motor '{motor.reference}' is built in and cannot be removed")
        assert self.user_dir is not None
        (self.user_dir / f"{motor.reference}.toml").unlink()


def _motor_file(path: Path, builtin: bool) -> Motor:
    """One catalog file; its errors name it by its place in the catalog (``built-in motors/M.toml``, ``user
    motors/M.toml``), never by its server path."""
    place = f"{'built-in' if builtin else 'user'} motors/{path.name}"
    motor = motor_from_text(path.read_text(encoding="utf-8"), place, builtin)
    if motor.reference != path.stem:
        raise FileFormatError(place, 1, f"reference '{motor.reference}' must equal the file name '{path.stem}'")
    return motor


def _motor_files(directory: Path | None) -> list[Path]:
    if directory is None or not directory.is_dir():
        return []
    return sorted(path for path in directory.glob("*.toml") if not path.name.startswith("."))
