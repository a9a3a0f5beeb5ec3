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
    "stdmsgs": 4.5,  # the standard ROS messages of a world: model only, for ros/ and bag/
    "adapt": 5,
    "ros": 5,
    "bag": 5.5,  # a run as an MCAP bag: engine, stdmsgs; used by cli/ and api/
    "falsify": 5,
    "cli": 6,
    "api": 6,
    "gym": 7,
}
MODULES = sorted(p for p in PKG.rglob("*.py") if p.parent != PKG)


def module_name(path: Path) -> str:
    """``amsa_phys.ros.runtime.leaf`` for ``amsa_phys/ros/runtime/leaf.py`` (a package's
    ``__init__.py`` is the package)."""
    parts = list(path.relative_to(PKG.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


KNOWN = {module_name(p) for p in PKG.rglob("*.py")}


def imports_of(path: Path, source: str | None = None, top_level: bool = False) -> set[str]:
    """The ``amsa_phys`` modules ``path`` imports, relative imports of any depth resolved
    (``from ...engine import x`` in ``ros/runtime/``), ``from pkg import module`` as the
    module. ``top_level``: only imports run when the module loads (not those inside
    functions, nor under ``if TYPE_CHECKING:``) — the ones that can make a circle."""
    tree = ast.parse(path.read_text() if source is None else source)
    me = module_name(path)
    package = me if path.name == "__init__.py" else me.rpartition(".")[0]
    nodes: list[ast.AST] = []

    def collect(body: list[ast.stmt]) -> None:
        for node in body:
            if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
                continue
            nodes.append(node)
            for field in ("body", "orelse", "finalbody"):
                if isinstance(node, ast.If | ast.Try) and hasattr(node, field):
                    collect(getattr(node, field))
            for handler in getattr(node, "handlers", []):
                collect(handler.body)

    if top_level:
        collect(tree.body)
    else:
        nodes = list(ast.walk(tree))
    found = set()
    for node in nodes:
        if isinstance(node, ast.Import):
            found |= {a.name for a in node.names if a.name.startswith("amsa_phys")}
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - (node.level - 1)]
                full = ".".join([*base, *([node.module] if node.module else [])])
            else:
                full = node.module or ""
            if full == "amsa_phys" or full.startswith("amsa_phys."):
                for alias in node.names:
                    sub = f"{full}.{alias.name}"
                    found.add(sub if sub in KNOWN else full)
    return found - {me}


def imported_packages(path: Path) -> set[str]:
    """The layers (``model``, ``engine``, ...) ``path`` imports from."""
    return {m.split(".")[1] for m in imports_of(path) if m.count(".") >= 1} & set(LAYER)


@pytest.mark.parametrize("path", MODULES, ids=[str(p.relative_to(PKG)) for p in MODULES])
def test_no_upward_or_sideways_imports(path: Path) -> None:
    own = path.relative_to(PKG).parts[0]
    for other in imported_packages(path) - {own}:
        assert LAYER[other] < LAYER[own], f"{path.relative_to(PKG)} imports {other}"


def test_relative_imports_of_any_depth_are_seen() -> None:
    """A three-dot import from ``ros/runtime`` names its layer (the old check missed it)."""
    path = PKG / "ros" / "runtime" / "leaf.py"
    code = "from ...engine.runner import Simulation\nfrom ..graph import x\nfrom . import rosio\n"
    assert imports_of(path, code) == {
        "amsa_phys.engine.runner",
        "amsa_phys.ros.graph",
        "amsa_phys.ros.runtime.rosio",
    }
    assert imported_packages(path) >= {"ros"}
    sideways = PKG / "engine" / "x.py"
    assert {m.split(".")[1] for m in imports_of(sideways, "from ..runs import sweep\n")} == {"runs"}


def circles() -> list[list[str]]:
    """Groups of modules that import each other when they load (Tarjan's components)."""
    graph = {module_name(p): imports_of(p, top_level=True) & KNOWN for p in PKG.rglob("*.py")}
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    out: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            group = []
            while True:
                w = stack.pop()
                group.append(w)
                if w == v:
                    break
            if len(group) > 1:
                out.append(sorted(group))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def test_no_import_circles_even_inside_a_package() -> None:
    assert circles() == []


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
