"""The import layering of `backend/servostudio` is the one `docs/architecture.md` states, so the two cannot drift.

The page's layer table ("may import") and its table of composition edges are the rules; every `import` and
`from … import` of the package, at any depth of the syntax tree (imports inside functions included), is checked
against them. The first tests run the checker on small made-up packages, so that what makes it fail is itself
tested; the last ones run it on the real package and the real page.
"""

from __future__ import annotations

import ast
import re
from dataclasses import dataclass
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
PACKAGE = REPO / "backend" / "servostudio"
ARCHITECTURE = REPO / "docs" / "architecture.md"
PACKAGE_NAME = "servostudio"
ROOT_INIT = "__init__.py"  # `servostudio.__version__`: every module may import the package root
SIMULATOR_NEVER_IMPORTS = ("drive/", "services/", "api/")  # the product and its test double share no code under test
NONE_ALLOWED = "—"


@dataclass(frozen=True)
class Row:
    """One row of the layer table: the folders or modules it covers and what they may import."""

    sources: tuple[str, ...]
    allowed: tuple[str, ...]


@dataclass(frozen=True)
class Rules:
    """The page's rules: the layer rows, and the module-to-module composition edges."""

    rows: tuple[Row, ...]
    composition: dict[str, tuple[str, ...]]


@dataclass(frozen=True)
class Edge:
    """One import: module `source` imports module `target` (both paths relative to the package), at `line`."""

    source: str
    target: str
    line: int


def _cells(line: str) -> list[str]:
    """The cells of a Markdown table line (`| a | b |` → `["a", "b"]`)."""
    return [cell.strip() for cell in line.strip().strip("|").split("|")]


def table_rows(markdown: str, last_header: str) -> list[list[str]]:
    """The body rows of the first table whose header's last cell is `last_header` (so the page's prose and other
    tables may change freely); fails the test if the page has no such table."""
    lines = markdown.splitlines()
    for number, line in enumerate(lines):
        if line.startswith("|") and _cells(line)[-1] == last_header:
            body = []
            for row in lines[number + 2 :]:
                if not row.startswith("|"):
                    break
                body.append(_cells(row))
            return body
    raise AssertionError(f"no table with a {last_header!r} column in the architecture page")


def _paths(cell: str) -> tuple[str, ...]:
    """The package paths a cell names: every `quoted` text, or nothing for the cell "—"."""
    if cell == NONE_ALLOWED:
        return ()
    paths = tuple(re.findall(r"`([^`]+)`", cell))
    assert paths, f"a rule cell must name paths in backticks or be {NONE_ALLOWED!r}: {cell!r}"
    return paths


def parse_rules(markdown: str) -> Rules:
    """Read the layer table (last column "may import") and the composition table ("why" after "may also import")."""
    rows = tuple(Row(_paths(cells[0]), _paths(cells[-1])) for cells in table_rows(markdown, "may import"))
    composition: dict[str, tuple[str, ...]] = {}
    for cells in table_rows(markdown, "why"):
        (module,) = _paths(cells[0])
        composition[module] = _paths(cells[1])
    return Rules(rows, composition)


def missing_paths(rules: Rules, package: Path) -> list[str]:
    """Every folder (`name/`) or module (`name.py`) the rules name that the package does not have."""
    named = {path for row in rules.rows for path in (*row.sources, *row.allowed)}
    named |= {path for module, allowed in rules.composition.items() for path in (module, *allowed)}
    exists = {path for path in named if (package / path).is_dir() == path.endswith("/") and (package / path).exists()}
    return sorted(named - exists)


def module_files(package: Path) -> list[str]:
    """Every Python module of the package, as a path relative to it (`drive/sdo.py`)."""
    return sorted(path.relative_to(package).as_posix() for path in package.rglob("*.py"))


def _module_path(package: Path, dotted: str) -> str:
    """The file of a dotted module name (`servostudio.drive.sdo` → `drive/sdo.py`), or of its longest existing
    prefix (an imported name that is not a module, e.g. `servostudio.drive.sdo.SdoEngine`)."""
    parts = dotted.split(".")[1:]
    while parts:
        base = package.joinpath(*parts)
        if (base / "__init__.py").is_file():
            return (base / "__init__.py").relative_to(package).as_posix()
        if base.with_suffix(".py").is_file():
            return base.with_suffix(".py").relative_to(package).as_posix()
        parts.pop()
    return ROOT_INIT


def _dotted_package(module: str) -> list[str]:
    """The package a module belongs to, as name parts (`drive/sdo.py` → `servostudio.drive`), for relative imports."""
    parts = [PACKAGE_NAME, *Path(module).with_suffix("").parts]
    return parts[:-1]


def _imported_names(node: ast.Import | ast.ImportFrom, module: str) -> list[str]:
    """The dotted names an import statement loads; `from a import b` counts as `a.b` (which may be a module)."""
    if isinstance(node, ast.Import):
        return [alias.name for alias in node.names]
    if node.level:
        base = _dotted_package(module)[: len(_dotted_package(module)) - node.level + 1]
        stem = ".".join([*base, *([node.module] if node.module else [])])
    else:
        stem = node.module or ""
    return [f"{stem}.{alias.name}" for alias in node.names]


def imports_of(package: Path, module: str) -> list[Edge]:
    """Every import of the package's own modules made anywhere in `module` (functions, `TYPE_CHECKING` blocks and
    `try` blocks included: an import is a dependency wherever it is written)."""
    tree = ast.parse((package / module).read_text(encoding="utf-8"), filename=module)
    edges = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import | ast.ImportFrom):
            for name in _imported_names(node, module):
                if name == PACKAGE_NAME or name.startswith(PACKAGE_NAME + "."):
                    edges.append(Edge(module, _module_path(package, name), node.lineno))
    return list(dict.fromkeys(edges))  # `from a import b, c` of one module is one edge


def _covers(path: str, module: str) -> bool:
    """Whether a rule path (a folder `name/` or a module `name.py`) stands for `module`."""
    return module.startswith(path) if path.endswith("/") else module == path


def row_of(rules: Rules, module: str) -> Row | None:
    """The layer row a module belongs to: the row naming it exactly, else the one with the longest folder."""
    candidates = [(len(path), row) for row in rules.rows for path in row.sources if _covers(path, module)]
    return max(candidates, key=lambda candidate: candidate[0])[1] if candidates else None


def is_allowed(rules: Rules, edge: Edge) -> bool:
    """An edge inside one row, to the package root, or to a path its row or a composition edge names."""
    row = row_of(rules, edge.source)
    assert row is not None, f"{edge.source} belongs to no layer row"
    allowed = (*row.sources, *row.allowed, *rules.composition.get(edge.source, ()))
    return edge.target == ROOT_INIT or any(_covers(path, edge.target) for path in allowed)


def all_edges(package: Path) -> list[Edge]:
    """Every import edge between two modules of the package."""
    return [edge for module in module_files(package) for edge in imports_of(package, module)]


def violations(rules: Rules, package: Path) -> list[str]:
    """A readable line per module outside every row and per import edge the rules do not allow."""
    orphans = [
        f"{module}: in no row of the layer table" for module in module_files(package) if not row_of(rules, module)
    ]
    if orphans:
        return orphans
    return [
        f"{edge.source}:{edge.line} imports {edge.target}, which its row does not allow"
        for edge in all_edges(package)
        if not is_allowed(rules, edge)
    ]


def unused_composition_edges(rules: Rules, package: Path) -> list[str]:
    """Composition edges no import needs any more: the page would state an edge that does not exist."""
    used = {
        (edge.source, path)
        for edge in all_edges(package)
        for path in rules.composition.get(edge.source, ())
        if _covers(path, edge.target)
    }
    return [
        f"{module} → {path}"
        for module, paths in rules.composition.items()
        for path in paths
        if (module, path) not in used
    ]


def simulator_breaches(rules: Rules, package: Path) -> list[str]:
    """Simulator edges into the product's upper layers, allowed by the page or present in the code."""
    sim_rules = [path for row in rules.rows if "sim/" in row.sources for path in row.allowed]
    sim_rules += [path for module, paths in rules.composition.items() if module.startswith("sim/") for path in paths]
    stated = [f"the page lets sim/ import {path}" for path in sim_rules if path.startswith(SIMULATOR_NEVER_IMPORTS)]
    coded = [
        f"{edge.source}:{edge.line} imports {edge.target}"
        for edge in all_edges(package)
        if edge.source.startswith("sim/") and edge.target.startswith(SIMULATOR_NEVER_IMPORTS)
    ]
    return stated + coded


# --- the checker on made-up packages -------------------------------------------------------------------------------

TOY_PAGE = """\
| folder | layer | may import |
|---|---|---|
| `low/` | bottom | — |
| `high/` | top | `low/` |
| `sim/` | test double | `low/codec.py` |
| `__init__.py` | root | — |

| module | may also import | why |
|---|---|---|
| `high/compose.py` | `sim/net.py` | the one composition point |
"""


def write_package(root: Path, modules: dict[str, str]) -> Path:
    """A package `servostudio` under `root` with the given module texts (every folder gets an `__init__.py`)."""
    package = root / PACKAGE_NAME
    for module, text in {ROOT_INIT: "", **modules}.items():
        path = package / module
        for folder in [path.parent, *path.parent.parents]:
            if folder == root:
                break
            folder.mkdir(parents=True, exist_ok=True)
            (folder / "__init__.py").touch()
        path.write_text(text, encoding="utf-8")
    return package


TOY_MODULES = {
    "low/codec.py": "",
    "low/other.py": "from servostudio.low import codec\n",
    "high/compose.py": "from servostudio.low.codec import x\n\ndef f():\n    from servostudio.sim import net\n",
    "sim/net.py": "from ..low import codec\nfrom servostudio import __version__\n",
}


def test_the_checker_accepts_a_package_that_keeps_the_rules(tmp_path: Path) -> None:
    package = write_package(tmp_path, TOY_MODULES)
    rules = parse_rules(TOY_PAGE)
    assert missing_paths(rules, package) == []
    assert violations(rules, package) == []
    assert unused_composition_edges(rules, package) == []


@pytest.mark.parametrize(
    "module, text, reported",
    [
        ("low/up.py", "import servostudio.high.compose\n", "low/up.py:1 imports high/compose.py"),
        (
            "low/late.py",
            "def f():\n    from servostudio.high import compose\n",
            "low/late.py:2 imports high/compose.py",
        ),
        ("sim/wide.py", "from ..low import other\n", "sim/wide.py:1 imports low/other.py"),
        ("high/other.py", "from servostudio.sim.net import Network\n", "high/other.py:1 imports sim/net.py"),
    ],
    ids=["upward", "inside-a-function", "relative-beyond-a-module-rule", "composition-is-per-module"],
)
def test_the_checker_fails_on_an_edge_the_page_does_not_allow(
    tmp_path: Path, module: str, text: str, reported: str
) -> None:
    package = write_package(tmp_path, {**TOY_MODULES, module: text})
    assert violations(parse_rules(TOY_PAGE), package) == [f"{reported}, which its row does not allow"]


def test_the_checker_fails_on_a_folder_or_module_that_does_not_exist(tmp_path: Path) -> None:
    package = write_package(tmp_path, {"low/codec.py": "", "sim/net.py": ""})
    assert missing_paths(parse_rules(TOY_PAGE), package) == ["high/", "high/compose.py"]


def test_the_checker_fails_on_a_module_in_no_row(tmp_path: Path) -> None:
    package = write_package(tmp_path, {**TOY_MODULES, "extra/thing.py": ""})
    assert violations(parse_rules(TOY_PAGE), package)[0].startswith("extra/__init__.py: in no row")


def test_the_checker_fails_on_a_composition_edge_no_code_needs(tmp_path: Path) -> None:
    package = write_package(tmp_path, {**TOY_MODULES, "high/compose.py": ""})
    assert unused_composition_edges(parse_rules(TOY_PAGE), package) == ["high/compose.py → sim/net.py"]


def test_the_checker_fails_when_the_simulator_reaches_the_product(tmp_path: Path) -> None:
    page = TOY_PAGE.replace("| `sim/` | test double | `low/codec.py` |", "| `sim/` | test double | `drive/` |")
    package = write_package(
        tmp_path, {**TOY_MODULES, "drive/sdo.py": "", "sim/cheat.py": "import servostudio.drive.sdo"}
    )
    assert simulator_breaches(parse_rules(page), package) == [
        "the page lets sim/ import drive/",
        "sim/cheat.py:1 imports drive/sdo.py",
    ]


# --- the real package and the real page ----------------------------------------------------------------------------


@pytest.fixture(scope="module")
def rules() -> Rules:
    return parse_rules(ARCHITECTURE.read_text(encoding="utf-8"))


def test_every_path_the_page_names_exists(rules: Rules) -> None:
    assert missing_paths(rules, PACKAGE) == []


def test_every_import_keeps_the_layering_of_the_page(rules: Rules) -> None:
    assert violations(rules, PACKAGE) == []


def test_every_composition_edge_of_the_page_is_used(rules: Rules) -> None:
    assert unused_composition_edges(rules, PACKAGE) == []


def test_the_simulator_never_imports_drive_services_or_api(rules: Rules) -> None:
    assert simulator_breaches(rules, PACKAGE) == []
