"""The dependencies in `pyproject.toml` tell the truth: a runtime dependency is one the running product imports.

A package only tests or benchmarks use (`canopen`, the independent CANopen peer) belongs to the `test` or `bench`
extra, and one nothing imports yet (`plotly`, until the oscilloscope) to no list at all. A product extra (`profibus`:
pyprofibus, GPL) is imported by the product only where it is needed, and the core runs without it. Imports are read
with `ast` (inside functions too) and mapped to distributions through the installed packages' metadata.
"""

from __future__ import annotations

import ast
import re
import sys
import tomllib
from importlib.metadata import packages_distributions
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
PYPROJECT = tomllib.loads((REPO / "pyproject.toml").read_text(encoding="utf-8"))["project"]

#: Runtime dependencies the product needs without importing them itself, and why.
NOT_IMPORTED = {"python-multipart": "FastAPI parses the EDS upload route's File fields with it"}
OWN_MODULES = {"servostudio", "tests", "conftest"}
#: extras of the product itself (not of its tests): imported by the product, installed on demand
PRODUCT_EXTRAS = ("profibus",)


def distribution(requirement: str) -> str:
    """The normalised distribution name of a requirement (`uvicorn[standard]>=0.29` → `uvicorn`)."""
    match = re.match(r"[A-Za-z0-9._-]+", requirement)
    assert match, requirement
    return re.sub(r"[-_.]+", "-", match.group()).lower()


def declared(*extras: str) -> set[str]:
    """The runtime dependencies, plus those of the given extras."""
    requirements = [
        *PYPROJECT["dependencies"],
        *(r for extra in extras for r in PYPROJECT["optional-dependencies"][extra]),
    ]
    return {distribution(requirement) for requirement in requirements}


def imported_top_names(folder: Path) -> set[str]:
    """The top-level names of every absolute import under `folder` that is neither the standard library nor ours."""
    names: set[str] = set()
    for path in folder.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), filename=str(path))):
            if isinstance(node, ast.Import):
                names |= {alias.name.split(".")[0] for alias in node.names}
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                names.add(node.module.split(".")[0])
    siblings = {path.stem for path in folder.glob("*.py")}  # a script importing its neighbour (bench/ helpers)
    return names - set(sys.stdlib_module_names) - OWN_MODULES - siblings - {"__future__"}


def imported_distributions(folder: Path) -> set[str]:
    """The installed distributions that provide the third-party imports under `folder` (fails on an import no
    installed distribution provides: it could not run here either)."""
    providers = packages_distributions()
    unknown = sorted(name for name in imported_top_names(folder) if name not in providers)
    assert not unknown, f"imports under {folder.name}/ that no installed distribution provides: {unknown}"
    return {distribution(dist) for name in imported_top_names(folder) for dist in providers[name]}


def test_every_runtime_dependency_is_imported_by_the_product() -> None:
    unused = declared() - imported_distributions(REPO / "backend" / "servostudio") - set(NOT_IMPORTED)
    assert not unused, f"runtime dependencies the product does not import (move them to an extra): {sorted(unused)}"


def test_everything_the_product_imports_is_a_runtime_dependency() -> None:
    missing = imported_distributions(REPO / "backend" / "servostudio") - declared(*PRODUCT_EXTRAS)
    assert not missing, f"the product imports these, but [project] dependencies do not list them: {sorted(missing)}"


def test_the_gpl_master_is_an_optional_extra_imported_only_for_a_serial_line() -> None:
    """pyprofibus (GPL-2.0-or-later) stays out of the core: only its adapter imports it at module level, and the
    opener imports the adapter inside the function that opens a serial PROFIBUS line (README "Licence")."""
    assert "pyprofibus" not in declared() and "pyprofibus" in declared("profibus")
    backend = REPO / "backend" / "servostudio"
    importers = sorted(
        str(path.relative_to(backend)) for path in backend.rglob("*.py") if "pyprofibus" in imported_top_names_of(path)
    )
    assert importers == ["transport/profibus/pyprofibus_master.py"]


def imported_top_names_of(path: Path) -> set[str]:
    """The top-level names a file imports at module level."""
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    names = {alias.name.split(".")[0] for node in tree.body if isinstance(node, ast.Import) for alias in node.names}
    return names | {node.module.split(".")[0] for node in tree.body if isinstance(node, ast.ImportFrom) and node.module}


@pytest.mark.parametrize("folder, extra", [("tests", "test"), ("bench", "bench")])
def test_tests_and_benchmarks_import_only_what_their_extra_installs(folder: str, extra: str) -> None:
    missing = imported_distributions(REPO / folder) - declared(extra)
    assert not missing, (
        f"{folder}/ imports these, but neither the runtime nor the {extra!r} extra lists them: {missing}"
    )


def test_the_independent_peer_is_no_runtime_dependency() -> None:
    assert "canopen" not in declared()
    assert "canopen" in declared("test") and "canopen" in declared("bench")
