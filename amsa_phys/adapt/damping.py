"""A damping rule: a lower gain once the follower swings, its threshold read from the sweep.

A higher gain in force when the context changes under it (very worn motors' gain on motors
that recover) starts a swing that the robust gain, barely damped on strong motors, carries
on for minutes after the fallback: the motor estimate cannot tell it from a right high gain
that reverses now and then, since both make the window's command cancel out and the
estimate unsure. How fast the follower travels does tell them apart: a rover tracking its
leader under a cell's own best gain travels at about the leader's speed, a swinging one two
to six times faster (the path counts backward travel as forward).

The sweep measures it, as data: a requirement ``always(M.pathSpeed <= C)`` in the swept
scenario gives each run's fastest path speed (C less the robustness) for an estimator ``M``
with a ``pathSpeed`` and a ``valid`` output. The *fastest* is the largest seed mean of it
at any cell's chosen point; the rule sets the point ``steps`` grid steps below the robust
point (a lower gain) when ``M`` is unsure and its path speed is above ``factor`` times the
fastest, for ``hold`` seconds, and only while ``M``'s held estimate lies where some cell rule
sets another point than the robust one (a swing starts only there); and ``M``'s fallback to
the robust point waits until the path speed is below ``RELEASE`` times the fastest, so it
does not restart the swing. Nothing here reads a held-out sequence.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..errors import ConfigError
from ..model.scenario import Scenario
from .table import SweepTable, read_table

#: The damping rule fires above this multiple of the fastest path speed under a chosen point
#: (on the shipped box: 0.28 m/s at the nominal cell's robust gain, swings 0.56-1.7 m/s).
FACTOR = 1.5
#: The motor fallback to the robust point waits for the path speed to fall below this
#: multiple of the fastest: the robust gain, set on a swing still under way, carries it on.
RELEASE = 1.25
#: Grid steps below the robust point the damping rule sets (the shipped box: Kv 0.1).
STEPS = 2
#: Seconds the swing must show before the damping rule fires.
HOLD = 3.0

_SPEED = re.compile(
    r"^\s*always\s*\(\s*([A-Za-z_]\w*)\.pathSpeed\s*<=\s*([0-9]+(?:\.[0-9]*)?(?:[eE][+-]?[0-9]+)?)\s*\)\s*$"
)


@dataclass
class Damping:
    """The damping rule's inputs and the rule, as ``derive`` reports them."""

    leaf: str
    fastest: float
    speed: float
    release: float
    point: dict[str, Any]
    rule: dict[str, Any]


def speed_requirement(scenario: Scenario) -> tuple[str, str, float] | None:
    """(estimator, requirement name, bound) of the swept scenario's path-speed requirement."""
    for entry in scenario.data.get("expect") or []:
        if not isinstance(entry, dict) or not isinstance(entry.get("stl"), str):
            continue
        match = _SPEED.match(entry["stl"])
        name = entry.get("name")
        if match and isinstance(name, str):
            return match.group(1), name, float(match.group(2))
    return None


def damping(
    results: Path,
    scenario: Scenario,
    table: SweepTable,
    chosen: dict[tuple[Any, ...], tuple[Any, ...]],
    robust: tuple[Any, ...],
    used: set[str],
    factor: float = FACTOR,
    steps: int = STEPS,
    hold: float = HOLD,
) -> Damping | None:
    """The damping rule for ``chosen`` (each cell's key -> its point), or None when the sweep
    does not measure the path speed, no estimator the rules read has one, or the robust
    point is already the lowest."""
    found = speed_requirement(scenario)
    if found is None or factor <= 0:
        return None
    leaf, name, bound = found
    buffers = scenario.world.buffers
    if not (
        f"{leaf}.pathSpeed" in buffers
        and f"{leaf}.valid" in buffers
        and any(s.rpartition(".")[0] == leaf for s in used)
    ):
        return None
    world, contexts = scenario.world, dict(scenario.data.get("sweep", {}).get("contexts", {}))
    try:
        speeds = read_table(results, f"robustness.{name}", world, contexts, set(table.context_axes))
    except ConfigError:
        return None  # a sweep run before the requirement was added
    fastest = 0.0
    for key, point in chosen.items():
        here = speeds.stats.get(key, {}).get(point)
        if here is None or not here.stable:
            return None  # a chosen point without a measured speed: no threshold to trust
        fastest = max(fastest, bound + here.mean)  # kept negated: bound - robustness
    lower = _below(table, robust, steps)
    if lower == robust or fastest <= 0:
        return None
    point = dict(zip(table.tuned, lower, strict=True))
    speed = round(factor * fastest, 3)
    rule = {
        "when": {f"{leaf}.valid": {"below": 0.5}, f"{leaf}.pathSpeed": {"above": speed}},
        "set": point,
        "hold": int(hold) if float(hold).is_integer() else hold,
        "label": f"damp, {leaf} swinging",
    }
    release = round(RELEASE * fastest, 3)
    return Damping(leaf, round(fastest, 3), speed, release, point, rule)


def _below(table: SweepTable, point: tuple[Any, ...], steps: int) -> tuple[Any, ...]:
    """``point`` moved ``steps`` grid steps down each tuned axis (stopping at the lowest)."""
    out = []
    for i, v in enumerate(point):
        values = sorted({p[i] for by in table.stats.values() for p in by})
        out.append(values[max(0, values.index(v) - steps)])
    return tuple(out)


def guarded(
    fallbacks: list[dict[str, Any]], valid: str, band: dict[str, dict[str, float]]
) -> list[dict[str, Any]]:
    """``fallbacks`` with one more after the damped estimator's: the robust point once it is
    unsure with its held value above the switched band, whatever the path speed.

    The damping rule reads only a held value inside the band, and the fallback waits for the
    swing to end; a higher gain set just before the motors recover, whose last sure window
    already reads them above the band, then swings on with no rule left to fire (the cell
    transitions' largest losses, ``benchmarks/adapt_transitions.py``). Above the band no cell
    sets a higher gain, so the robust point is right there, swing or not."""
    out = []
    for rule in fallbacks:
        out.append(rule)
        when = rule["when"]
        released = any(k.endswith(".pathSpeed") and "below" in b for k, b in when.items())
        if valid not in when or not released:
            continue  # not the fallback that waits for a swing to end
        above = {s: {"above": b["below"]} for s, b in band.items() if "below" in b}
        if not above:
            continue
        extra = {k: v for k, v in rule.items() if k not in ("when", "label")}
        leaf = valid.rpartition(".")[0]
        out.append(
            {
                "when": {valid: {"below": 0.5}, **above},
                **extra,
                "label": f"robust, {leaf} unsure above the switched band",
            }
        )
    return out
