"""The optimizer of ``amsa-phys tune``: golden sections for one parameter, CMA-ES for several.

The objective (a tail measure over contexts and seeds) is deterministic: every candidate is
run on the same contexts with the same seeds (common random numbers), so two candidates
differ by their parameters alone and the answer is reproducible. For one parameter (the
usual case: a gain) a coarse grid over the range first brackets the best (the objective of
a gain is steep near instability and may have a flat plateau, which misleads a local
method started blind), then a golden-section search refines between the best grid
point's neighbours (a dozen lines here rather than SciPy as a dependency; it needs no
derivative and shrinks the bracket by 0.618 per evaluation). For two or more, CMA-ES (the
``cmaes`` package, which ``falsify`` already uses) searches the unit box from its centre
(step 0.3). Every evaluation counts against ``budget``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np


@dataclass
class Trial:
    """One evaluated point: its parameter values and its objective (lower is better)."""

    values: tuple[float, ...]
    score: float


@dataclass
class Search:
    """Every trial, in the order run."""

    trials: list[Trial] = field(default_factory=list)

    @property
    def best(self) -> Trial:
        """The lowest score (first found on a tie)."""
        return min(self.trials, key=lambda t: t.score)


def minimise(
    objective: Callable[[tuple[float, ...]], float],
    bounds: list[tuple[float, float]],
    budget: int,
    seed: int = 1,
    integer: list[bool] | None = None,
) -> Search:
    """Minimise ``objective`` over the box ``bounds`` in at most ``budget`` evaluations."""
    integer = integer or [False] * len(bounds)
    search = Search()
    cache: dict[tuple[float, ...], float] = {}

    def f(x: tuple[float, ...]) -> float:
        point = tuple(
            float(round(v)) if whole else float(round(v, 6))
            for v, whole in zip(x, integer, strict=True)
        )
        if point not in cache:
            if len(search.trials) >= budget:
                return math.inf
            cache[point] = objective(point)
            search.trials.append(Trial(point, cache[point]))
        return cache[point]

    if len(bounds) == 1:
        _one(f, bounds[0], budget)
    else:
        _many(f, bounds, budget, seed)
    return search


def _one(f: Callable[[tuple[float, ...]], float], bound: tuple[float, float], budget: int) -> None:
    lo, hi = bound
    n = max(2, min(budget, max(3, budget // 2)))
    grid = [float(x) for x in np.linspace(lo, hi, n)]
    scores = [f((x,)) for x in grid]
    k = int(np.argmin(scores))
    a, b = grid[max(0, k - 1)], grid[min(n - 1, k + 1)]
    ratio = (math.sqrt(5.0) - 1.0) / 2.0
    c, d = b - ratio * (b - a), a + ratio * (b - a)
    fc, fd = f((c,)), f((d,))
    for _ in range(budget - n - 2):
        if fc <= fd:
            b, d, fd = d, c, fc
            c = b - ratio * (b - a)
            fc = f((c,))
        else:
            a, c, fc = c, d, fd
            d = a + ratio * (b - a)
            fd = f((d,))


def _many(
    f: Callable[[tuple[float, ...]], float],
    bounds: list[tuple[float, float]],
    budget: int,
    seed: int,
) -> None:
    from cmaes import CMA  # imported when tuning

    lo = np.array([b[0] for b in bounds])
    span = np.array([b[1] - b[0] for b in bounds])
    dims = len(bounds)
    cma = CMA(mean=np.full(dims, 0.5), sigma=0.3, bounds=np.array([[0.0, 1.0]] * dims), seed=seed)
    spent = 0
    while spent < budget:
        told = []
        for _ in range(cma.population_size):
            x = cma.ask()
            score = f(tuple(lo + span * x))
            spent += 1
            told.append((x, score if math.isfinite(score) else 1e300))
        if len(told) == cma.population_size:
            cma.tell(told)
