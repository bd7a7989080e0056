"""Procedure results kept in the project, under their axis: ``<project>/<axis>/procedures/<name>-<UTC time>.json``.

Each file is written atomically (``fsutil.atomic_write``) under the project's lock; listed newest first.
"""

from __future__ import annotations

import json
from datetime import UTC, datetime
from pathlib import Path

from servostudio.errors import InvalidInput
from servostudio.services.audit import current_actor
from servostudio.services.projects.fsutil import atomic_write
from servostudio.services.projects.layout import PROCEDURES_DIR, TEMP_PREFIX
from servostudio.services.projects.store import ProjectStore


class IncompleteTarget(InvalidInput):
    """A project without an axis, or an axis without a project."""


class ResultStore:
    def __init__(self, projects: ProjectStore) -> None:
        self.projects = projects

    def check(self, project: str | None, axis: str | None) -> None:
        """Refuse a target that cannot be saved to, before the procedure runs (unknown project or axis: 404)."""
        if project is None and axis is None:
            return
        if project is None or axis is None:
            raise IncompleteTarget("a result is saved under a project's axis: give both project and axis")
        with self.projects.read(project) as view:
            view.axis(axis)

    def save(self, project: str, axis: str, name: str, result: dict[str, object], when: datetime | None = None) -> str:
        """Write the result with who ran it (the acting user: the report's "who"); returns its path in the project
        (``<axis>/procedures/<file>``)."""
        result = {**result, "user": result.get("user") or current_actor().user}
        moment = (when or datetime.now(UTC)).strftime("%Y%m%dT%H%M%S.%fZ")
        with self.projects.edit(project) as edit:
            directory = edit.axis_directory(axis) / PROCEDURES_DIR
            directory.mkdir(parents=True, exist_ok=True)
            path = directory / f"{name}-{moment}.json"
            atomic_write(path, json.dumps(result, indent=2, sort_keys=False) + "\n")
            return f"{edit.axis(axis).name}/{PROCEDURES_DIR}/{path.name}"

    def list(self, project: str, axis: str) -> list[dict[str, object]]:
        """Every saved result of the axis, newest first (a file that cannot be read names itself in ``error``)."""
        with self.projects.read(project) as view:
            directory = view.axis_directory(axis) / PROCEDURES_DIR
            files = (
                sorted(directory.glob("*.json"), key=lambda path: path.name.rsplit("-", 1)[-1], reverse=True)
                if directory.is_dir()
                else []
            )
            return [_load(path) for path in files if not path.name.startswith(TEMP_PREFIX)]


def _load(path: Path) -> dict[str, object]:
    try:
        loaded = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as error:
        return {"file": path.name, "error": f"{path.name}: cannot be read ({error})"}
    return (
        {"file": path.name, **loaded}
        if isinstance(loaded, dict)
        else {"file": path.name, "error": f"{path.name}: not a JSON object"}
    )
