"""The frequency responses saved under an axis, as the REST API and the Bode page reach them: list, open, the pinned
CSV, the standalone HTML, delete.

``store.py`` reads a project directory without the project's lock (the report works offline from the files alone);
here every read holds the project's shared lock and every delete its exclusive one, and an unknown project or axis
is refused (not found) before any file is looked at, as the scope's saved captures are.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from servostudio.services.frequency import store
from servostudio.services.frequency.export import frequency_html
from servostudio.services.projects import layout
from servostudio.services.projects.names import check_name
from servostudio.services.projects.store import ProjectStore


class SavedFrequency:
    """Saved frequency responses of a project store."""

    def __init__(self, projects: ProjectStore) -> None:
        self.projects = projects

    def list(self, project: str, axis: str) -> list[dict[str, Any]]:
        """Summaries, newest first; a damaged sidecar lists with its ``error``."""
        with self.projects.read(project) as view:
            return store.list_saved(view.directory, view.axis(axis).name)

    def open(self, project: str, axis: str, name: str) -> dict[str, Any]:
        """The full result dict with its points."""
        with self.projects.read(project) as view:
            return store.load(view.directory, view.axis(axis).name, name)

    def csv(self, project: str, axis: str, name: str) -> str:
        """The saved result as the pinned CSV (``freq_hz,magnitude_db,phase_deg,coherence``), re-written from what
        was read: the same text the store wrote."""
        return store.points_csv(self.open(project, axis, name))

    def html(self, project: str, axis: str, name: str, compare: Sequence[str] = ()) -> str:
        """The standalone HTML of one result, with the results named in ``compare`` overlaid."""
        with self.projects.read(project) as view:
            canonical = view.axis(axis).name
            results = [store.load(view.directory, canonical, each) for each in (name, *compare)]
        return frequency_html(results, f"{project} / {canonical}")

    def delete(self, project: str, axis: str, name: str) -> None:
        """Remove a saved result, a damaged one too: its sidecar first (it is gone once its sidecar is), then its
        CSV."""
        check_name(name, "frequency response")
        with self.projects.edit(project) as edit:
            directory = edit.axis_directory(axis) / layout.FREQUENCY_DIR
            sidecar = directory / f"{name}.json"
            if not sidecar.is_file():
                raise store.FrequencyResultNotFound(f"axis '{axis}' has no saved frequency response '{name}'")
            sidecar.unlink()
            (directory / f"{name}.csv").unlink(missing_ok=True)
