"""Fixtures of the project tests: a fresh project store per test on the built-in dictionaries."""

from __future__ import annotations

from pathlib import Path

import pytest

from servostudio.od import builtin_library
from servostudio.services.projects import Bus, ProjectService


@pytest.fixture
def service(tmp_path: Path) -> ProjectService:
    return ProjectService(tmp_path / "store", builtin_library(), motors_dir=tmp_path / "builtin-motors")


@pytest.fixture
def sim_project(service: ProjectService) -> ProjectService:
    """Project 'p' with bus 'sim' and no axis."""
    service.store.create("p", "test project", (Bus("sim", "sim", 1_000_000),))
    return service
