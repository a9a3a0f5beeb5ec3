"""A formula nested too deeply is refused in one line, whatever its operators.

Every walk of the formula tree (signals, sampling, horizon, monitor, messages) recurses once
per level, so a chain of ``+`` as much as a tower of parentheses must be bounded before any
of them runs; the deepest formula accepted is judged through all of them.
"""

from __future__ import annotations

from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

from amsa_phys.cli.main import main
from amsa_phys.stl.monitor import evaluate, explain
from amsa_phys.stl.requirement import check_formula
from amsa_phys.stl.syntax import MAX_TREE_DEPTH, FormulaError, parse

ROOT = Path(__file__).resolve().parent.parent.parent

DEEP = {
    "sum chain": " + ".join(["t"] * 990) + " > 0",
    "product chain": " * ".join(["t"] * 990) + " > 0",
    "abs": "abs(" * 400 + "t" + ")" * 400 + " > 0",
    "unary minus": "t > " + "- " * 1900 + "0",
    "and chain": " and ".join(["t>0"] * 450),
    "until chain": " until ".join(["t>0"] * 400),
    "not over a chain": "not (" + " + ".join(["t"] * 900) + " > 0)",
    "parentheses": "(" * 100 + "t > 0" + ")" * 100,
}


@pytest.mark.parametrize("formula", DEEP.values(), ids=DEEP.keys())
def test_a_deep_formula_is_refused_as_nested_too_deeply(formula: str) -> None:
    with pytest.raises(FormulaError, match=r"^nested too deeply"):
        parse(formula)


@pytest.mark.parametrize("formula", DEEP.values(), ids=DEEP.keys())
def test_a_scenario_with_a_deep_formula_is_refused_in_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], formula: str
) -> None:
    path = tmp_path / "s.yaml"
    path.write_text(
        f"world: {ROOT / 'worlds' / 'mde_challenge.yaml'}\nduration: 10\n"
        f'expect:\n  - {{stl: "{formula}", name: x}}\n'
    )
    assert main(["validate", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"error: {path}:4: expect[0]")
    assert "nested too deeply" in err
    assert err.count("\n") == 1
    assert "Traceback" not in err


def test_the_deepest_formula_accepted_goes_through_every_walk() -> None:
    """The bound is what keeps the walks inside the stack: the deepest tree it lets through
    is checked, judged and explained like any other."""
    terms = MAX_TREE_DEPTH - 1  # a + chain of k terms, compared: k + 1 levels
    formula = " + ".join(["t"] * terms) + " >= 0"
    node = parse(formula)
    assert node.depth == MAX_TREE_DEPTH
    with pytest.raises(FormulaError, match="nested too deeply"):
        parse(" + ".join(["t"] * (terms + 1)) + " >= 0")
    check_formula(formula, [], Fraction(10), Fraction(10))
    t = np.arange(5) / 10
    ev = evaluate(node, {"t": t}, Fraction(1, 10))
    assert ev.robustness[0] == 0
    atom, _i = explain(ev)
    assert atom.text().startswith("((((")
