"""Shared test code lives in ``tests/support/``: no test module, conftest or helper imports from a test module or a
conftest (a conftest is pytest's, loaded once per folder; importing it, or a test module, runs it a second time under
another name and ties one folder's tests to another's). Folder-local helpers (``tests/od/peers.py``) may stay put."""

from __future__ import annotations

import ast
from pathlib import Path

TESTS = Path(__file__).resolve().parent


def imported_modules(path: Path, tests: Path = TESTS) -> list[str]:
    """Every ``from X import`` of the file (inside functions too), relative ones resolved to their ``tests.`` name."""
    package = ".".join(path.relative_to(tests.parent).with_suffix("").parts[:-1])
    found = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom):
            base = package.rsplit(".", node.level - 1)[0] if node.level else ""
            found.append(".".join(part for part in (base, node.module or "") if part))
        elif isinstance(node, ast.Import):
            found.extend(alias.name for alias in node.names)
    return found


def is_test_code(module: str) -> bool:
    last = module.rsplit(".", 1)[-1]
    return module.startswith("tests.") and (last == "conftest" or last.startswith("test_"))


def test_no_file_imports_a_test_module_or_a_conftest():
    offenders = [
        f"{path.relative_to(TESTS)}: {module}"
        for path in sorted(TESTS.rglob("*.py"))
        for module in imported_modules(path)
        if is_test_code(module)
    ]
    assert not offenders, "move what they share into tests/support/:\n" + "\n".join(offenders)


def test_the_check_sees_relative_and_absolute_imports(tmp_path):
    assert is_test_code("tests.services.scope.conftest") and is_test_code("tests.api.test_api_scope")
    assert not is_test_code("tests.support.scope_bench") and not is_test_code("tests.od.peers")
    module = tmp_path / "tests" / "browser" / "test_x.py"
    module.parent.mkdir(parents=True)
    module.write_text("from .conftest import screenshot\nfrom ..support import browser\n", encoding="utf-8")
    assert imported_modules(module, tmp_path / "tests") == ["tests.browser.conftest", "tests.support"]
