"""Imports flow one way: model -> engine -> physics|sensors|control|interop -> plots|view -> runs
-> ros -> cli|api -> gym."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PKG = Path(__file__).resolve().parent.parent.parent / "amsa_phys"
LAYER = {
    "model": 0,
    "engine": 1,
    "physics": 2,
    "sensors": 2,
    "control": 2,
    "interop": 2,
    "plots": 3,
    "view": 3,
    "runs": 4,
    "ros": 5,
    "falsify": 5,
    "cli": 6,
    "api": 6,
    "gym": 7,
}
MODULES = sorted(p for p in PKG.rglob("*.py") if p.parent != PKG)


def imported_packages(path: Path) -> set[str]:
    tree = ast.parse(path.read_text())
    own = path.relative_to(PKG).parts[0]
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module is not None:
            if node.level == 2:
                found.add(node.module.split(".")[0])
            elif node.level == 0 and node.module.startswith("amsa_phys."):
                found.add(node.module.split(".")[1])
        if isinstance(node, ast.ImportFrom) and node.level == 1:
            found.add(own)
    return found & set(LAYER)


@pytest.mark.parametrize("path", MODULES, ids=[str(p.relative_to(PKG)) for p in MODULES])
def test_no_upward_or_sideways_imports(path: Path) -> None:
    own = path.relative_to(PKG).parts[0]
    for other in imported_packages(path) - {own}:
        assert LAYER[other] < LAYER[own], f"{path.relative_to(PKG)} imports {other}"


def test_only_physics_imports_pymunk() -> None:
    for path in PKG.rglob("*.py"):
        tree = ast.parse(path.read_text())
        names = {
            a.name.split(".")[0]
            for n in ast.walk(tree)
            if isinstance(n, ast.Import)
            for a in n.names
        }
        names |= {
            n.module.split(".")[0]
            for n in ast.walk(tree)
            if isinstance(n, ast.ImportFrom) and n.module and n.level == 0
        }
        if "pymunk" in names:
            assert path.relative_to(PKG).parts[0] == "physics", path
