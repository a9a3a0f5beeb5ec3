"""``adapt --validate``: derived rules scored on held-out context sequences.

A rule set is only worth running if it beats keeping the robust fixed choice on contexts
it was *not* derived from. The held-out sequences are drawn from the sweep's own box
(``tune.contexts``: levels between the sweep's levels, random switch instants, behaviours
from the contexts' list), with their own random seed. Each is run for ``seeds`` seeds three
ways: the robust fixed choice (no rules), the rules (starting from the robust choice), and
the *oracle* schedule: at each true switch instant, the best choice of the sweep cell
nearest the new context (what perfect estimators and rules would set; for a context between
the sweep's levels it is the nearest cell's best, not a re-tuned one). The rules *lose*
when on any sequence their seed-mean metric is more than ``tolerance`` above the robust
choice's.
"""

from __future__ import annotations

import math
import statistics
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from ..model.scenario import Scenario
from ..tune.contexts import Axis, Sequence, box, sequences
from ..tune.evaluate import evaluate
from .derive import Cell, Derivation


@dataclass
class Row:
    """One held-out sequence: its contexts and the seed means of the three ways."""

    sequence: Sequence
    robust: float
    oracle: float
    adaptive: float

    @property
    def change(self) -> float:
        """The rules' mean relative to the robust choice's (-0.1: 10 % better)."""
        if not (math.isfinite(self.robust) and self.robust > 0):
            return math.inf
        return self.adaptive / self.robust - 1.0


def nearest(cells: list[Cell], axes: list[Axis], context: dict[str, Any]) -> Cell:
    """The cell whose context is nearest ``context`` (scaled by each axis's span)."""

    def distance(cell: Cell) -> float:
        d = 0.0
        for a in axes:
            mine, theirs = context.get(a.key), cell.context.get(a.key)
            if a.choices:
                d += 0.0 if mine == theirs else 1.0
            else:
                d += abs(float(mine) - float(theirs)) / ((a.hi - a.lo) or 1.0)
        return d

    return min((c for c in cells if c.best), key=distance)


def validate(
    scenario: Scenario,
    found: Derivation,
    contexts: dict[str, dict[str, Any]],
    count: int = 5,
    seeds: int = 3,
    duration: float = 600.0,
    seed: int = 1000,
    report: Callable[[str], None] | None = None,
) -> list[Row]:
    """Score ``found``'s rules on ``count`` held-out sequences; one :class:`Row` each."""
    axes = box(scenario, contexts)
    rows = []
    for sequence in sequences(axes, count, duration, seed):
        oracle_plan = [
            (at, nearest(found.cells, axes, sets).best) for at, sets in sequence.segments
        ]
        ways: dict[str, list[float]] = {"robust": [], "oracle": [], "adaptive": []}
        for s in range(1, seeds + 1):
            cases = {
                "robust": evaluate(scenario, sequence, found.robust, s, found.metric, duration),
                "adaptive": evaluate(
                    scenario, sequence, found.robust, s, found.metric, duration, found.rules
                ),
                "oracle": evaluate(
                    scenario, sequence, {}, s, found.metric, duration, None, oracle_plan
                ),
            }
            for way, value in cases.items():
                ways[way].append(math.inf if value is None else value)
        row = Row(sequence, *(statistics.fmean(ways[w]) for w in ("robust", "oracle", "adaptive")))
        rows.append(row)
        if report is not None:
            report(line(row))
    return rows


def line(row: Row) -> str:
    """One table row: the three means and the rules' change against the robust choice."""
    return (
        f"{row.robust:.4g} | {row.oracle:.4g} | {row.adaptive:.4g} | {100 * row.change:+.1f} % "
        f"| {row.sequence.describe()}"
    )


HEADER = "robust | oracle | rules | rules vs robust | held-out sequence"


def loses(rows: list[Row], tolerance: float) -> list[Row]:
    """The sequences on which the rules are more than ``tolerance`` worse than robust."""
    return [r for r in rows if r.change > tolerance]
