"""Choosing points of a context sweep's grid: the lowest, the safe, the robust.

A derived rule's gain must not sit one grid step from instability, and the robust fixed gain
is the one whose worst cell is least bad; these are questions about the sweep's grid alone,
asked by ``derive`` (and answerable without any estimator), so they live apart from it.
"""

from __future__ import annotations

import statistics
from typing import Any

from .table import SweepTable


def lowest(by_point: dict[tuple[Any, ...], Any]) -> tuple[Any, ...] | None:
    """The point with the lowest seed mean among those every run of which finished."""
    stable = [p for p, s in by_point.items() if s.stable]
    return min(stable, key=lambda p: (by_point[p].mean, p)) if stable else None


def neighbours(table: SweepTable, point: tuple[Any, ...]) -> list[tuple[Any, ...]]:
    """The grid points one step from ``point`` along each tuned axis (in any cell)."""
    values = [sorted({p[i] for by in table.stats.values() for p in by}) for i in range(len(point))]
    out = []
    for i, v in enumerate(point):
        j = values[i].index(v)
        for k in (j - 1, j + 1):
            if 0 <= k < len(values[i]):
                out.append((*point[:i], values[i][k], *point[i + 1 :]))
    return out


def is_safe(
    table: SweepTable, cell: tuple[Any, ...], point: tuple[Any, ...], margin: float
) -> bool:
    """``point`` finished in ``cell`` and its neighbours did, none more than ``margin`` worse."""
    by_point = table.stats[cell]
    here = by_point.get(point)
    if here is None or not here.stable:
        return False
    for other in neighbours(table, point):
        near = by_point.get(other)
        if near is None:
            continue  # not swept in this cell: nothing known against it
        if not near.stable or near.mean > (1.0 + margin) * here.mean:
            return False
    return True


def safe_best(
    table: SweepTable,
    cell: tuple[Any, ...],
    margin: float,
    robust: tuple[Any, ...] | None = None,
    near: float = 0.0,
) -> tuple[Any, ...] | None:
    """The cell's lowest-mean safe point (None if none is safe); of the safe points within
    ``near`` of it, the fewest grid steps from ``robust``."""
    by_point = table.stats[cell]
    ranked = sorted(
        (p for p, s in by_point.items() if s.stable), key=lambda p: (by_point[p].mean, p)
    )
    safe = [p for p in ranked if is_safe(table, cell, p, margin)]
    if not safe or robust is None or near <= 0:
        return safe[0] if safe else None
    level = [p for p in safe if by_point[p].mean <= (1.0 + near) * by_point[safe[0]].mean]
    return min(level, key=lambda p: (steps(table, p, robust), by_point[p].mean, p))


def steps(table: SweepTable, a: tuple[Any, ...], b: tuple[Any, ...]) -> int:
    """Grid steps between two points (summed over the tuned axes)."""
    out = 0
    for i in range(len(a)):
        values = sorted({p[i] for by in table.stats.values() for p in by})
        if a[i] in values and b[i] in values:
            out += abs(values.index(a[i]) - values.index(b[i]))
    return out


def robust_point(table: SweepTable, margin: float) -> tuple[Any, ...] | None:
    """The point with the least worst-case seed mean over the cells (safe ones first)."""
    cells = list(table.stats)
    common = set.intersection(*(set(table.stats[c]) for c in cells)) if cells else set()
    everywhere = [p for p in common if all(table.stats[c][p].stable for c in cells)]
    if not everywhere:
        return None

    def worst(p: tuple[Any, ...]) -> tuple[float, float, tuple[Any, ...]]:
        means = [table.stats[c][p].mean for c in cells]
        return (max(means), statistics.fmean(means), p)

    safe = [p for p in everywhere if all(is_safe(table, c, p, margin) for c in cells)]
    return min(safe or everywhere, key=worst)
