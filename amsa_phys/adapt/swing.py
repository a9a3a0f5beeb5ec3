"""A swing supervisor: back to the robust point once the loop visibly swings, its level from
the sweep.

In the spirit of the Simplex architecture: the cell rules may set a higher gain than the
robust one on the estimators' word, and a short-window observer of the loop itself
(``SwingMonitor``: the distance's turning points) takes that gain back when the loop swings
farther than any right gain makes it swing. A gain set for weaker motors than the rover
has, or set while the follower catches up from far behind, overshoots by metres; a right
gain, in its own context, swings far less.

The sweep measures it, as data: a requirement ``always[a:b](S.amplitude <= C)`` (or
``always(...)``) in the swept scenario gives each run's largest half swing (C less the
robustness) for an estimator ``S`` with an ``amplitude`` and a ``valid`` output. The
*largest* is the largest seed mean of it at any cell's chosen point (the robust point's
own swing on healthy motors included: a right gain's swing, wherever it is); the rule sets
the robust point once ``S`` is sure and its amplitude is above ``factor`` times the largest,
for ``hold`` seconds, and every cell rule that sets another point than the robust one
waits for the amplitude to fall below that level again (which ``S``, reporting its
window's largest half swing, does a window after the swing died out). Nothing here reads a
held-out sequence.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..errors import ConfigError
from ..model.scenario import Scenario
from .cellrules import whole
from .damping import Damping
from .table import SweepTable, read_table

#: The rule fires above this multiple of the largest swing under a chosen point.
FACTOR = 1.5
#: Seconds the swing must show before the rule fires.
HOLD = 2.0

_NUMBER = r"[0-9]+(?:\.[0-9]*)?(?:[eE][+-]?[0-9]+)?"
_AMPLITUDE = re.compile(
    rf"^\s*always\s*(?:\[\s*{_NUMBER}\s*:\s*{_NUMBER}\s*\])?\s*\(\s*([A-Za-z_]\w*)\.amplitude"
    rf"\s*<=\s*({_NUMBER})\s*\)\s*$"
)


@dataclass
class Swing:
    """The swing rule's inputs and the rule, as ``derive`` reports them."""

    leaf: str
    largest: float
    level: float
    rule: dict[str, Any]

    def guard(self) -> dict[str, dict[str, float]]:
        """The condition a cell rule setting a higher point than the robust one adds."""
        return {f"{self.leaf}.amplitude": {"below": self.level}}

    def supervise(
        self,
        cell_rules: list[dict[str, Any]],
        fallbacks: list[dict[str, Any]],
        robust: dict[str, Any],
        damping: Damping | None,
        holds: bool = True,
    ) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
        """(cell rules, fallbacks) with the swing rule: after the damping rule (not on a swing
        the damping rule is taking, or the two would undo each other), and every cell rule
        setting another point than the robust one waiting for the swing to end (``holds``)."""
        held = self.guard() if holds else {}
        cells = [
            {**r, "when": {**r["when"], **held}} if r["set"] != robust else r for r in cell_rules
        ]
        if damping is not None:
            self.rule["when"][f"{damping.leaf}.pathSpeed"] = {"below": damping.speed}
        after = 0 if damping is None else fallbacks.index(damping.rule) + 1
        return cells, [*fallbacks[:after], self.rule, *fallbacks[after:]]


def swing_requirement(scenario: Scenario) -> tuple[str, str, float] | None:
    """(estimator, requirement name, bound) of the swept scenario's swing requirement."""
    for entry in scenario.data.get("expect") or []:
        if not isinstance(entry, dict) or not isinstance(entry.get("stl"), str):
            continue
        match = _AMPLITUDE.match(entry["stl"])
        name = entry.get("name")
        if match and isinstance(name, str):
            return match.group(1), name, float(match.group(2))
    return None


def swing(
    results: Path,
    scenario: Scenario,
    table: SweepTable,
    chosen: dict[tuple[Any, ...], tuple[Any, ...]],
    robust: tuple[Any, ...],
    factor: float = FACTOR,
    hold: float = HOLD,
) -> Swing | None:
    """The swing rule for ``chosen`` (each cell's key -> its point), or None when the sweep
    does not measure the swing, its estimator lacks the outputs, or no cell sets a point
    other than the robust one (nothing to take back)."""
    found = swing_requirement(scenario)
    if found is None or factor <= 0 or all(p == robust for p in chosen.values()):
        return None
    leaf, name, bound = found
    buffers = scenario.world.buffers
    if not (f"{leaf}.amplitude" in buffers and f"{leaf}.valid" in buffers):
        return None
    world, contexts = scenario.world, dict(scenario.data.get("sweep", {}).get("contexts", {}))
    try:
        swings = read_table(results, f"robustness.{name}", world, contexts, set(table.context_axes))
    except ConfigError:
        return None  # a sweep run before the requirement was added
    largest = 0.0
    for key, point in chosen.items():
        here = swings.stats.get(key, {}).get(point)
        if here is None or not here.stable:
            return None  # a chosen point without a measured swing: no level to trust
        largest = max(largest, bound + here.mean)  # kept negated: bound - robustness
    if largest <= 0:
        return None
    level = round(factor * largest, 3)
    rule: dict[str, Any] = {
        "when": {f"{leaf}.valid": {"above": 0.5}, f"{leaf}.amplitude": {"above": level}},
        "set": dict(zip(table.tuned, robust, strict=True)),
        "hold": whole(hold),
    }
    window = world.leaves[leaf].params.get("window")
    if isinstance(window, int | float) and not isinstance(window, bool) and window > hold:
        rule["dwell"] = whole(window)  # one window: the swing's turning points leave it
    rule["label"] = f"robust, {leaf} swinging"
    return Swing(leaf, round(largest, 3), level, rule)
