"""The best grid point of a sweep, for the line printed at its end.

The summary plot stars it, but a sweep run from a script or over ssh is read in the
terminal: the point and its value belong on the last line too. "Best" is the lowest seed
mean of a metric (an error, a distance, a count) and the highest of a requirement's
robustness, as the summary's star (``requirements.objective.higher_is_better``, the rule
``tune`` and ``falsify`` follow).
"""

from __future__ import annotations

import math
from collections import defaultdict
from typing import Any

from ..model.wording import plural
from ..requirements.objective import higher_is_better


def best_point(
    rows: list[dict[str, Any]], axes: list[str], metric: str
) -> tuple[tuple[tuple[str, Any], ...], float, int, int] | None:
    """(the grid point, its seed mean, its seeds, how many other points tie with it), or
    None when no run has a value (all failed, or none reached the metric)."""
    by_point: dict[tuple[tuple[str, Any], ...], list[float]] = defaultdict(list)
    for r in rows:
        v = r.get(metric)
        if r.get("error") or isinstance(v, bool) or not isinstance(v, int | float):
            continue
        if math.isfinite(v):
            by_point[tuple((a, r[a]) for a in axes)].append(float(v))
    if not by_point:
        return None
    means = {p: sum(vs) / len(vs) for p, vs in by_point.items()}
    sense = -1.0 if higher_is_better(metric) else 1.0
    point = min(means, key=lambda p: (sense * means[p], str(p)))
    best = means[point]
    ties = sum(1 for p, m in means.items() if p != point and math.isclose(m, best, rel_tol=1e-9))
    return point, best, len(by_point[point]), ties


def best_line(rows: list[dict[str, Any]], axes: list[str], metric: str) -> str | None:
    """``best (lowest mean rms_error): Kv=0.2 -> 1.396 (2 seeds)``; None if nothing to say."""
    found = best_point(rows, axes, metric)
    if found is None:
        return None
    point, mean, seeds, ties = found
    where = ", ".join(f"{k}={v}" for k, v in point) or "the scenario as written"
    mean_of = "mean " if seeds > 1 else ""
    most = "highest" if higher_is_better(metric) else "lowest"
    line = f"best ({most} {mean_of}{metric}): {where} -> {mean:.6g} ({plural(seeds, 'seed')})"
    if ties:
        line += f"; tied with {plural(ties, 'other grid point')}"
    return line
