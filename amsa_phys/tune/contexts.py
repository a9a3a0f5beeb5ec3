"""Context distributions: the box a sweep's contexts span, and random sequences drawn from it.

A sweep's ``contexts`` name parameter sets (``worn motors: {motorCoef: 50}``); their union
is the *box*: for each context parameter, the values the contexts give it. A parameter whose
values are numbers on a scale (``motorCoef`` 100, 50, 25) is drawn uniformly between its
least and greatest value (rounded for an integer parameter), so held-out contexts fall
*between* the levels rules were derived on; a parameter whose values are codes (a leader's
``behavior``: an estimator maps each code to its own level) is drawn from the values the
contexts list. A *sequence* is a run's timeline of such contexts with
random switch instants, each segment at least ``min_segment`` seconds long.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..model.scenario import Scenario


@dataclass(frozen=True)
class Axis:
    """One context parameter: continuous in ``[lo, hi]``, or one of ``choices``."""

    key: str
    lo: float = 0.0
    hi: float = 0.0
    choices: tuple[Any, ...] = ()
    integer: bool = False

    def draw(self, rng: np.random.Generator) -> Any:
        """A value of this parameter."""
        if self.choices:
            return self.choices[int(rng.integers(len(self.choices)))]
        value = float(rng.uniform(self.lo, self.hi))
        return round(value) if self.integer else round(value, 3)


def box(scenario: Scenario, contexts: dict[str, dict[str, Any]]) -> list[Axis]:
    """The axes the named ``contexts`` span (their parameters, at the scenario's values when a
    context leaves one out)."""
    from ..control.estimators.watches import watches  # which parameters are codes to an estimator

    codes = {w.key for w in watches(scenario.world) if w.estimates.levels}
    keys = sorted({k for sets in contexts.values() for k in sets})
    out = []
    for key in keys:
        leaf, _, param = key.rpartition(".")
        spec = scenario.world.leaves[leaf]
        base = _initial(scenario, key, spec.params.get(param))
        values = sorted({sets.get(key, base) for sets in contexts.values()})
        kind = spec.template.param(spec.template.canonical(param)).type
        numeric = all(isinstance(v, int | float) and not isinstance(v, bool) for v in values)
        if key not in codes and numeric and len(values) > 1 and kind in ("float", "int"):
            out.append(Axis(key, float(values[0]), float(values[-1]), integer=kind == "int"))
        else:
            out.append(Axis(key, choices=tuple(values)))
    return out


def _initial(scenario: Scenario, key: str, default: Any) -> Any:
    for change in scenario.timeline.initial:
        if change.key == key:
            return change.value
    return default


@dataclass(frozen=True)
class Sequence:
    """A run's contexts: ``segments`` of (start instant, parameter values)."""

    segments: tuple[tuple[float, dict[str, Any]], ...]

    def timeline(self) -> list[dict[str, Any]]:
        """The segments after the first as scenario ``timeline:`` entries."""
        return [{"at": at, "set": dict(sets)} for at, sets in self.segments[1:]]

    def describe(self) -> str:
        """``0 s {motorCoef 71.2, behavior 4}; 230 s {...}`` (short parameter names)."""
        parts = []
        for at, sets in self.segments:
            inner = ", ".join(f"{k.rsplit('.', 1)[-1]} {v:g}" for k, v in sets.items())
            parts.append(f"{at:g} s {{{inner}}}")
        return "; ".join(parts)


#: the shortest context of a held-out sequence (s): an estimator's window (30 s by default)
#: fills well inside it
MIN_SEGMENT_S = 60.0


def sequences(
    axes: list[Axis],
    n: int,
    duration: float,
    seed: int,
    segments: tuple[int, int] = (2, 4),
    min_segment: float = MIN_SEGMENT_S,
) -> list[Sequence]:
    """``n`` random context sequences over ``duration`` seconds (reproducible by ``seed``)."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        count = int(rng.integers(segments[0], segments[1] + 1))
        count = max(1, min(count, int(duration // min_segment)))
        free = duration - count * min_segment
        cuts = np.sort(rng.uniform(0.0, free, count - 1)) if count > 1 else np.array([])
        starts = [0.0] + [round(float(c) + (i + 1) * min_segment) for i, c in enumerate(cuts)]
        out.append(Sequence(tuple((at, {a.key: a.draw(rng) for a in axes}) for at in starts)))
    return out
