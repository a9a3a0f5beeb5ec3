"""Tests import their shared helpers by module name, never through a ``tests.`` package.

``tests/`` is not a package: pytest puts ``tests/`` on ``sys.path`` (``pythonpath`` in
pyproject.toml), so ``from sweepfiles import ...`` works however pytest is started.
``from tests.sweepfiles import ...`` only works when the checkout's root also happens to be on
the path (``python -m pytest`` from the root), and CI, which runs plain ``pytest``, fails to
collect the file.
"""

from __future__ import annotations

import ast
from pathlib import Path

TESTS = Path(__file__).resolve().parents[1]


def _bad_imports(source: str) -> list[str]:
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            if node.module == "tests" or node.module.startswith("tests."):
                found.append(f"{node.lineno}: from {node.module}")
        elif isinstance(node, ast.Import):
            found += [
                f"{node.lineno}: import {a.name}"
                for a in node.names
                if a.name == "tests" or a.name.startswith("tests.")
            ]
    return found


def test_the_check_finds_a_tests_package_import() -> None:
    assert _bad_imports("from tests.sweepfiles import x\nimport tests.golden\n") == [
        "1: from tests.sweepfiles",
        "2: import tests.golden",
    ]
    assert _bad_imports("from sweepfiles import x\nfrom . import y\n") == []


def test_no_test_imports_through_a_tests_package() -> None:
    bad = {
        str(p.relative_to(TESTS)): hits
        for p in sorted(TESTS.rglob("*.py"))
        if (hits := _bad_imports(p.read_text(encoding="utf-8")))
    }
    assert bad == {}, f"import the helper by its module name instead: {bad}"
