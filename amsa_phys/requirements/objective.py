"""One objective name to one number: ``rms_error``, ``phase1.max_distance``, ``robustness.NAME``.

Every command that optimises over runs (``falsify``, ``tune``, ``adapt``) accepts the same
names, and must agree on two things: where the number is in a run's metrics, and which way
is better. Both live here so they cannot drift apart.

* A metric (``rms_error``, ``phase<i>.<metric>``) measures error, distance, time or counts:
  **lower is better** (``falsify`` maximises it to find the worst case, as it always has).
* ``robustness.NAME`` is the signed margin by which a run meets the STL requirement NAME
  (negative: violated): **higher is better** (``falsify`` minimises it; ``tune`` maximises
  its worst case).

The metrics may be a run's ``metrics.json`` document (``overall``, ``phases``,
``requirements``) or a flat row of a sweep's ``results.csv`` (``rms_error``,
``phase1.rms_error``, ``robustness.NAME``): both shapes are read the same.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Mapping
from typing import Any

from ..model.metrics import METRICS
from ..model.suggest import did_you_mean

#: The prefix of a requirement's objective name and of its ``results.csv`` column.
ROBUSTNESS_PREFIX = "robustness."

_PHASE = re.compile(r"phase(\d+)\.(.+)")


def requirement_of(name: str) -> str | None:
    """The requirement an objective name is about (``robustness.band`` -> ``band``), or None."""
    if name.startswith(ROBUSTNESS_PREFIX):
        return name[len(ROBUSTNESS_PREFIX) :]
    return None


def column(requirement: str) -> str:
    """The ``results.csv`` column (and objective name) of a requirement's robustness."""
    return ROBUSTNESS_PREFIX + requirement


def higher_is_better(name: str) -> bool:
    """The sense of an objective: True for a robustness, False for a metric."""
    return requirement_of(name) is not None


def _number(value: Any) -> float | None:
    """A cell as a float; None for missing, empty or NaN (a metric never reached)."""
    if value is None or value == "":
        return None
    out = float(value)
    return None if math.isnan(out) else out


def objective_value(metrics: Mapping[str, Any], name: str) -> tuple[float | None, bool]:
    """``(value, higher_is_better)`` of objective ``name`` in one run's ``metrics``.

    ``value`` is None when the run has no such number (a metric that never settled, a phase
    the run never reached, a requirement it did not judge); the caller decides what a
    missing value costs (``falsify`` counts it as the worst there is). A name that is
    neither a metric nor ``robustness.NAME`` raises ``KeyError`` (validate names up front
    with :func:`unknown_objective`).
    """
    better = higher_is_better(name)
    if name in metrics and not isinstance(metrics.get(name), Mapping):
        return _number(metrics[name]), better  # a flat results.csv row
    req = requirement_of(name)
    if req is not None:
        entry = (metrics.get("requirements") or {}).get(req)
        if entry is None:
            return None, True
        return _number(entry.get("robustness")), True
    m = _PHASE.fullmatch(name)
    if m is not None and m.group(2) in METRICS:
        phases = metrics.get("phases") or []
        i = int(m.group(1))
        return (_number(phases[i].get(m.group(2))) if i < len(phases) else None), False
    if name in METRICS:
        return _number((metrics.get("overall") or {}).get(name)), False
    raise KeyError(name)


def unknown_objective(name: str, n_phases: int, requirements: Iterable[str]) -> str | None:
    """Why ``name`` is no objective of a scenario with ``n_phases`` phases and these
    requirement names (None if it is one), with a did-you-mean."""
    names = list(requirements)
    req = requirement_of(name)
    if req is not None:
        if req in names:
            return None
        known = ", ".join(names) if names else "none (add an expect: {stl: ..., name: ...})"
        return f"unknown requirement {req!r}{did_you_mean(req, names)}; known: {known}"
    if name in METRICS:
        return None
    m = _PHASE.fullmatch(name)
    if m is not None and m.group(2) in METRICS and int(m.group(1)) < n_phases:
        return None
    pool = [*METRICS, *(f"phase{i}.{k}" for i in range(n_phases) for k in METRICS)]
    pool += [column(r) for r in names]
    return f"unknown objective {name!r}{did_you_mean(name, pool)}; known: metrics " + (
        ", ".join(METRICS) + (", robustness.<requirement>" if names else "")
    )
