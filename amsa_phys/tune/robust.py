"""Tail measures of a set of case values (lower is better): worst case and CVaR.

``worst`` is the largest value: what the controller gives in its least favourable context
and seed. ``cvar`` (conditional value at risk, at level ``alpha``) is the mean of the worst
``alpha`` share of the values (at least one): with alpha 0.2 over 50 cases, the mean of the
10 worst. It is less swayed by one unlucky seed than the worst case and still penalises a
bad tail, which the mean alone hides. A case with no value (a fault, a metric never
reached) counts as infinitely bad under both.
"""

from __future__ import annotations

import math
from collections.abc import Sequence


def tail(values: Sequence[float | None], measure: str = "worst", alpha: float = 0.2) -> float:
    """The ``measure`` ("worst" or "cvar") of ``values``; ``inf`` if any has no value."""
    if not values or any(v is None for v in values):
        return math.inf
    ordered = sorted((float(v) for v in values if v is not None), reverse=True)
    if measure == "worst":
        return ordered[0]
    if measure == "cvar":
        k = max(1, math.ceil(alpha * len(ordered)))
        return sum(ordered[:k]) / k
    raise ValueError(f"unknown tail measure {measure!r} (worst, cvar)")
