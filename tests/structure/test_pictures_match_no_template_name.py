"""The pictures draw what templates declare (``Template.marks``), never a template by its
name: a scan of the drawing code for a built-in template's name, or a comparison with a
template's ``name()``, both of which would leave a user's own template undrawn."""

from __future__ import annotations

import ast
from pathlib import Path

from amsa_phys.model.template import BUILTINS

PKG = Path(__file__).resolve().parents[2] / "amsa_phys"
#: the code that draws or feeds a picture: the window and video, the plots, the Gymnasium
#: renderer, the marks read back from a trace and the plots' context from the world
DRAWING = [
    *sorted((PKG / "view").glob("*.py")),
    *sorted((PKG / "plots").glob("*.py")),
    PKG / "gym" / "render.py",
    PKG / "tracemarks.py",
    PKG / "runs" / "plotjob.py",
]
#: every template name a world may hold that the package itself defines (the agent's
#: stand-in included)
NAMES = frozenset(BUILTINS) | {"agent"}


def _docstrings(tree: ast.AST) -> set[int]:
    """ids of the string constants that are docstrings (prose may name a template)."""
    out = set()
    for node in ast.walk(tree):
        body = getattr(node, "body", None)
        if isinstance(body, list) and body and isinstance(body[0], ast.Expr):
            value = body[0].value
            if isinstance(value, ast.Constant) and isinstance(value.value, str):
                out.add(id(value))
    return out


def _names_a_template(node: ast.AST) -> bool:
    """``x.name()`` or ``x.template_name``: a template's name."""
    if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute):
        return node.func.attr == "name" and not node.args
    return isinstance(node, ast.Attribute) and node.attr == "template_name"


def name_matches(path: Path) -> list[str]:
    """Where ``path`` holds a built-in template's name as a string, or compares a
    template's name with anything."""
    tree = ast.parse(path.read_text(), str(path))
    prose = _docstrings(tree)
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in prose:
            if node.value in NAMES:
                out.append(f"{path.name}:{node.lineno}: the template name {node.value!r}")
        elif isinstance(node, ast.Compare) and any(
            _names_a_template(n) for n in (node.left, *node.comparators)
        ):
            out.append(f"{path.name}:{node.lineno}: compares a template's name")
    return out


def test_no_drawing_code_recognises_a_template_by_name() -> None:
    assert all(p.is_file() for p in DRAWING)
    assert [m for p in DRAWING for m in name_matches(p)] == []


def test_the_scan_finds_a_name_matched(tmp_path: Path) -> None:
    """The scan is not blind: the two ways pictures used to recognise a template."""
    bad = tmp_path / "bad.py"
    bad.write_text(
        '"""A docstring may say GPS."""\n'
        'TEMPLATE = "frictionZone"\n'
        "def lidars(leaves):\n"
        "    return [p for p, leaf in leaves.items() if leaf.template.name() == x]\n"
    )
    assert name_matches(bad) == [
        "bad.py:2: the template name 'frictionZone'",
        "bad.py:4: compares a template's name",
    ]
