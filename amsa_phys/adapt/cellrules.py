"""The rules a derivation writes for the sweep's cells: one per cell's band of estimator
levels, and one per combination of bands no cell has (the nearest cell's best).

Why its own module: the bands and the nearest-cell rules are pure functions of the placed
cells' levels, tested on their own; ``derive.py`` places the cells and adds the fallbacks.
"""

from __future__ import annotations

import itertools
import math
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from .derive import Cell

#: Share of the distance between two levels left to no rule on each side of the midpoint.
GAP = 0.1


def whole(hold: float) -> float | int:
    """A time as the rules file writes it: an int when it is whole (``30``, not ``30.0``)."""
    return int(hold) if float(hold).is_integer() else hold


def band(ls: list[float], i: int) -> dict[str, float]:
    """The band of level ``ls[i]``: from the midpoints to its neighbours, less the gap."""
    bound: dict[str, float] = {}
    if i > 0:
        mid, step = (ls[i - 1] + ls[i]) / 2, ls[i] - ls[i - 1]
        bound["above"] = round(mid + GAP * step, 6)
    if i < len(ls) - 1:
        mid, step = (ls[i] + ls[i + 1]) / 2, ls[i + 1] - ls[i]
        bound["below"] = round(mid - GAP * step, 6)
    return bound


def cell_rules(cells: list[Cell], hold: float) -> list[dict[str, Any]]:
    """One rule per placed cell (cells at the same levels with the same best share one),
    then one per combination of bands no cell has (:func:`nearest_rules`)."""
    signals = sorted({s for c in cells for s in c.levels})
    levels = {s: sorted({c.levels[s] for c in cells if s in c.levels}) for s in signals}
    rules: list[dict[str, Any]] = []
    seen: dict[tuple[Any, ...], dict[str, Any]] = {}
    for cell in cells:
        when: dict[str, dict[str, float]] = {}
        for s in signals:
            ls = levels[s]
            if len(ls) < 2 or s not in cell.levels:
                continue
            when[s] = band(ls, ls.index(cell.levels[s]))
        if not when:
            continue
        key = (
            tuple(sorted((k, tuple(sorted(v.items()))) for k, v in when.items())),
            tuple(sorted(cell.best.items())),
        )
        if key in seen:
            seen[key]["label"] += f", {cell.name}"
            continue
        rule = {"when": when, "set": dict(cell.best), "hold": whole(hold), "label": cell.name}
        seen[key] = rule
        rules.append(rule)
    return rules + nearest_rules(cells, levels, hold)


def nearest_rules(
    cells: list[Cell], levels: dict[str, list[float]], hold: float
) -> list[dict[str, Any]]:
    """A rule for each combination of bands that no cell settles to: the nearest cell's best.

    A sweep need not cover every combination of its estimators' levels (a random leader
    with very worn motors, when it swept each alone). With no rule there, the gain in force
    stays -- whatever the last context set -- or the robust one; the oracle schedule
    ``adapt --validate`` compares with sets the nearest cell's best instead. So does this
    rule: nearest in the estimators' levels, each output's distance a share of its span.
    When two cells are equally near with different best values, no rule is written.
    """
    varying = [s for s, ls in levels.items() if len(ls) >= 2]
    full = [c for c in cells if c.best and all(s in c.levels for s in varying)]
    if not varying or not full:
        return []
    taken = {tuple(levels[s].index(c.levels[s]) for s in varying) for c in full}
    span = {s: levels[s][-1] - levels[s][0] for s in varying}
    out: list[dict[str, Any]] = []
    for combo in itertools.product(*(range(len(levels[s])) for s in varying)):
        if combo in taken:
            continue

        def distance(c: Cell, combo: tuple[int, ...] = combo) -> float:
            return sum(
                abs(c.levels[s] - levels[s][i]) / span[s]
                for s, i in zip(varying, combo, strict=True)
            )

        least = min(distance(c) for c in full)
        near = [c for c in full if math.isclose(distance(c), least)]
        if len({tuple(sorted(c.best.items())) for c in near}) > 1:
            continue  # equally near cells disagree: leave it to the gain in force
        out.append(
            {
                "when": {s: band(levels[s], i) for s, i in zip(varying, combo, strict=True)},
                "set": dict(near[0].best),
                "hold": whole(hold),
                "label": f"nearest {near[0].name} (no cell here)",
            }
        )
    return out
