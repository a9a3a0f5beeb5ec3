"""A recovery rule: the robust point at once when motors a high gain was set for recover.

A high gain set for very worn motors stays in force when those motors recover until the
motor estimate's 30 s window notices, and on strong motors that gain swings the follower
within seconds; the robust gain, set late, carries the swing on for minutes. The estimate's
``recent`` output (the same share over its ``recentWindow``, a few seconds) sees the
recovery before the command reverses: the follower, pushed by a worn motors' command on
strong motors, accelerates as those motors do.

Every threshold comes from the cell rules, as data: the rule guards the *lowest* cell that
switches away from the robust point (its band of the share is the lowest: the very worn
motors'), reads that cell's bands on the other estimators (the leader read straight: a high
gain's short windows on a random leader, which stops and starts, read high without any
recovery), and fires when the recent share is above every band where a cell sets another
point (no higher gain is right for motors that strong) while the held estimate is still
below the next switching cell's band (it has not caught up yet). It sets the robust point,
after one step of the estimator (the first short window that shows it: a few seconds later
the command reverses and the short window can no longer judge). Nothing here reads a
held-out sequence.
"""

from __future__ import annotations

from typing import Any

from ..model.scenario import Scenario


def recovery(
    scenario: Scenario, rules: list[dict[str, Any]], robust: dict[str, Any], signal: str
) -> dict[str, Any] | None:
    """The recovery rule for the estimate ``signal`` (``M.delivered``) given the cell
    ``rules``, or None when ``M`` has no recent share (``recentWindow`` 0, or no ``recent``
    output) or fewer than one cell switches away from ``robust`` on a band of ``signal``."""
    leaf = signal.rpartition(".")[0]
    recent = f"{leaf}.recent"
    window = _initial(scenario, leaf, "recentWindow")
    if recent not in scenario.world.buffers or not window or window <= 0:
        return None
    away = [r for r in rules if r["set"] != robust and signal in r["when"]]
    bands = [r["when"][signal] for r in away]
    if not bands or any("below" not in b for b in bands):
        return None
    top = max(b["below"] for b in bands)
    lowest = min(away, key=lambda r: r["when"][signal]["below"])
    floor = lowest["when"][signal]["below"]
    above = [b["above"] for b in bands if "above" in b and b["above"] >= floor]
    held = min(above) if above else top
    when: dict[str, Any] = {recent: {"above": top}, signal: {"below": held}}
    for other, band in lowest["when"].items():
        if other != signal and other.rpartition(".")[0] != leaf and not other.endswith(".valid"):
            when[other] = dict(band)
    step = 1.0 / float(scenario.world.leaves[leaf].freq)
    return {
        "when": when,
        "set": dict(robust),
        "hold": step,
        "dwell": step,
        "label": f"robust, {leaf} recovered",
    }


def _initial(scenario: Scenario, leaf: str, name: str) -> float | None:
    """The Leaf's parameter ``name`` at t = 0 (the world's, then the scenario's ``set``)."""
    value = scenario.world.leaves[leaf].params.get(name)
    for change in scenario.timeline.initial:
        if change.key == f"{leaf}.{name}":
            value = change.value
    ok = isinstance(value, int | float) and not isinstance(value, bool)
    return float(value) if ok else None
