"""Frequency responses saved in a project, under their axis: ``<project>/<axis>/frequency/NAME.csv`` + ``NAME.json``.

The CSV holds the points in exactly the pinned columns ``freq_hz,magnitude_db,phase_deg,coherence`` after
``# key: value`` comment lines (as the scope CSV); the JSON sidecar is the result dict (docs/frequency-response.md)
without its points. Both are written atomically under the project's lock, the CSV first and the sidecar last: a
result exists once its sidecar does. ``list_saved`` and ``load`` read a project directory directly, so the report
works offline from the files alone. Saved results are records, not part of the project's revision.

The markers are derived from the points, so a saved result is read with the markers its points have today
(``markers.markers_of``): one measured before a definition changed shows the current one (the anti-resonance once
marked on rigid plants, docs/frequency-response.md §6), never a marker the code no longer makes.
"""

from __future__ import annotations

import csv
import io
import json
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from servostudio.errors import Conflict, InvalidInput, NotFound
from servostudio.services.frequency import markers
from servostudio.services.projects import layout
from servostudio.services.projects.fsutil import atomic_write
from servostudio.services.projects.names import check_name, name_taken, timestamp_name
from servostudio.services.projects.store import ProjectStore

COLUMNS = ("freq_hz", "magnitude_db", "phase_deg", "coherence")
SUMMARY_KEYS = ("kind", "loop", "node", "device", "axis", "time", "user", "excitation", "markers", "aborted")


class FrequencyResultNotFound(NotFound):
    """No saved frequency response of that name on the axis."""


class FrequencyResultExists(Conflict):
    """A saved frequency response of that name exists on the axis already."""


class FrequencyFileError(InvalidInput):
    """A damaged frequency-response file; the message names the file and the line."""


def points_csv(result: Mapping[str, Any]) -> str:
    """The CSV text: comment lines (loop, node, device, time, excitation), the pinned header, one row per point."""
    out = io.StringIO()
    for key, value in _comments(result):
        out.write(f"# {key}: {value}\n")
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(COLUMNS)
    for point in result.get("points", []):
        writer.writerow([_number_text(point[column]) for column in COLUMNS])
    return out.getvalue()


def parse_points(text: str, label: str = "frequency.csv") -> list[dict[str, float]]:
    """The points of a CSV written by :func:`points_csv` (comment lines skipped); a damaged line names itself."""
    lines = [(number, line) for number, line in enumerate(text.splitlines(), 1) if not line.startswith("#")]
    if not lines or lines[0][1].strip() != ",".join(COLUMNS):
        raise FrequencyFileError(f"{label}: the header must be {','.join(COLUMNS)}")
    return [_row(number, line, label) for number, line in lines[1:] if line.strip()]


def save(projects: ProjectStore, project: str, axis: str, result: Mapping[str, Any], name: str | None = None) -> str:
    """Save ``result`` under ``name`` (default: its time, numbered when taken); returns the name. Taken: conflict."""
    with projects.edit(project) as edit:
        directory = edit.axis_directory(axis) / layout.FREQUENCY_DIR
        measured_at = str(result.get("time", ""))
        chosen = check_name(name, "frequency response") if name else timestamp_name(directory, measured_at, "bode")
        if name and name_taken(directory, chosen):
            raise FrequencyResultExists(f"axis '{axis}' has a frequency response named '{chosen}' already")
        directory.mkdir(parents=True, exist_ok=True)
        sidecar = {key: value for key, value in result.items() if key != "points"}
        atomic_write(directory / f"{chosen}.csv", points_csv(result))
        atomic_write(directory / f"{chosen}.json", json.dumps({**sidecar, "data": f"{chosen}.csv"}, indent=2) + "\n")
    return chosen


def list_saved(project_dir: Path, axis: str) -> list[dict[str, Any]]:
    """Summaries (the result without its points, plus ``name``) of every saved response of the axis, newest first;
    a sidecar that cannot be read lists with its ``error``."""
    directory = Path(project_dir) / axis / layout.FREQUENCY_DIR
    sidecars = sorted(directory.glob("*.json")) if directory.is_dir() else []
    summaries = [_summary(path, axis) for path in sidecars if not path.name.startswith(layout.TEMP_PREFIX)]
    return sorted(summaries, key=lambda summary: str(summary.get("time", "")), reverse=True)


def load(project_dir: Path, axis: str, name: str) -> dict[str, Any]:
    """The full result dict of a saved response, with its points read from the CSV."""
    check_name(name, "frequency response")
    directory = Path(project_dir) / axis / layout.FREQUENCY_DIR
    json_path, csv_path = directory / f"{name}.json", directory / f"{name}.csv"
    if not json_path.is_file():
        raise FrequencyResultNotFound(f"axis '{axis}' has no saved frequency response '{name}'")
    sidecar = _sidecar(json_path, axis)
    if not csv_path.is_file():
        raise FrequencyFileError(f"{_label(axis, csv_path)}: the file is missing")
    points = parse_points(csv_path.read_text(encoding="utf-8"), _label(axis, csv_path))
    stored = {key: value for key, value in sidecar.items() if key != "data"}
    return {**stored, "name": name, "points": points, "markers": _current_markers(sidecar, points)}


def _current_markers(sidecar: Mapping[str, Any], points: list[dict[str, float]]) -> Any:
    """The markers of the points by today's definitions; a result of an unknown loop keeps what it was saved with."""
    loop = sidecar.get("loop")
    return markers.markers_of(loop, points) if loop in ("plant", "closed") else sidecar.get("markers")


def _comments(result: Mapping[str, Any]) -> list[tuple[str, str]]:
    excitation = result.get("excitation") or {}
    return [
        ("kind", str(result.get("kind", "frequency_response"))),
        ("loop", str(result.get("loop", ""))),
        ("device", str(result.get("device", ""))),
        ("node", str(result.get("node", ""))),
        ("time", str(result.get("time", ""))),
        ("excitation", ", ".join(f"{key}={value}" for key, value in excitation.items())),
        ("magnitude", _magnitude_meaning(result)),
        ("aborted", str(result.get("aborted") or "")),
    ]


def _magnitude_meaning(result: Mapping[str, Any]) -> str:
    """A plant per N·m, or per A where the drive gave no torque constant (the excitation's ``input``)."""
    if result.get("loop") == "plant":
        per_ampere = (result.get("excitation") or {}).get("input") == "current"
        return f"dB of (velocity in rad/s) / ({'current in A' if per_ampere else 'torque in N*m'})"
    return "dB of actual / demanded velocity"


def _number_text(value: object) -> str:
    number = float(value)  # type: ignore[arg-type]
    return "nan" if math.isnan(number) else f"{number:.6g}"


def _row(number: int, line: str, label: str) -> dict[str, float]:
    cells = next(csv.reader([line]))
    if len(cells) != len(COLUMNS):
        raise FrequencyFileError(f"{label}:{number}: {len(COLUMNS)} values expected, {len(cells)} found")
    try:
        values = [float(cell) for cell in cells]
    except ValueError:
        raise FrequencyFileError(f"{label}:{number}: not a number in {line!r}") from None
    return dict(zip(COLUMNS, values, strict=True))


def _sidecar(path: Path, axis: str) -> dict[str, Any]:
    try:
        loaded = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as error:
        raise FrequencyFileError(f"{_label(axis, path)}: cannot be read ({error})") from None
    if not isinstance(loaded, dict):
        raise FrequencyFileError(f"{_label(axis, path)}: not a JSON object")
    return loaded


def _summary(path: Path, axis: str) -> dict[str, Any]:
    try:
        loaded = load(path.parents[2], axis, path.stem)
    except InvalidInput as error:  # a damaged file, or a name the store never gives
        return {"name": path.stem, "error": str(error)}
    return {"name": path.stem, **{key: loaded.get(key) for key in SUMMARY_KEYS}}


def _label(axis: str, path: Path) -> str:
    """How messages name a file: by its place in the project, never by a server path."""
    return f"{axis}/{layout.FREQUENCY_DIR}/{path.name}"
