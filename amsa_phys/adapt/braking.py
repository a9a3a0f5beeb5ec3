"""A braking rule: the damping point the instant a higher gain brakes harder than a right one.

A high gain set for worn motors that is still in force when they recover pushes the follower
past its reference fast; the damping rule (``damping.py``) sees the swing only once a 30 s
window shows it, and the robust gain set as the follower crosses its reference takes away the
braking that would stop the overshoot. What a wrong high gain does first is brake hard: on
strong motors its command overshoots to a braking no right gain commands. So the first
instant both wheels command a braking harder than ``level`` % while the motor estimate is
unsure and its held value lies where a cell set a higher gain, the damping point is set.

The level comes from the sweep, as data, in two kinds of runs:

- *catch-ups*: in a sweep that measures braking (below), a context of ``sweep.contexts``
  that repeats a cell's context with more parameters no estimator watches (the follower
  started 2 m behind its reference) is not a cell (``catch_ups``): it is that cell started
  away from its reference, read only here. A right gain switched in late (after the
  estimate's window and the rule's hold) catches up from behind and brakes as it arrives;
  the hardest it brakes, over the switching cells and their catch-ups at each cell's chosen
  point, is the *right* braking;
- the *wrong* braking: the least hard a switching cell's point brakes on a cell that keeps
  the robust point (or its catch-up) where that point swings, its seed mean more than
  ``SWINGS`` above the cell's lowest (a high gain on motors stronger than its own).

A requirement ``always(C.LeftPower >= -B or C.RightPower >= -B)`` in the swept scenario gives
each run's hardest braking on both wheels (B less the robustness). The level is the right
braking plus ``SPLIT`` of the way to the wrong one; when the wrong one is not above the right
one the sweep cannot tell them apart and no rule is written. Nothing here reads a held-out
sequence.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..errors import ConfigError
from ..model.scenario import Scenario
from .table import SweepTable, read_table

#: Where between the right braking (0) and the wrong one (1) the level sits. Screened on the
#: cell transitions (``python -m benchmarks.adapt_transitions``), no held-out draw.
SPLIT = 0.0
#: A point swings in a cell when its seed mean is more than this share above the cell's
#: lowest (the safe-best margin's default: a gain far worse than the cell's best).
SWINGS = 0.5

_NUM = r"([0-9]+(?:\.[0-9]*)?(?:[eE][+-]?[0-9]+)?)"
_SIG = r"([A-Za-z_]\w*\.[A-Za-z_]\w*)"
_BRAKING = re.compile(
    rf"^\s*always\s*\(\s*{_SIG}\s*>=\s*-\s*{_NUM}\s+or\s+{_SIG}\s*>=\s*-\s*{_NUM}\s*\)\s*$"
)


@dataclass
class Braking:
    """The braking rule's evidence and the rule, as ``derive`` reports them."""

    right: float  # % the hardest a chosen point brakes in its cell or catching up
    wrong: float  # % the least a switching point swinging on stronger motors brakes
    level: float  # % the rule's threshold on both wheels' command
    rule: dict[str, Any]


def catch_ups(contexts: dict[str, dict[str, Any]], watched: set[str]) -> dict[str, str]:
    """Each catch-up context's name -> the name of the cell it repeats: a context equal to
    another one plus parameters no estimator watches (and nothing else)."""

    def repeats(sets: dict[str, Any], base: dict[str, Any]) -> bool:
        extra = set(sets) - set(base)
        same = all(k in sets and sets[k] == v for k, v in base.items())
        return bool(extra) and not extra & watched and same

    out: dict[str, str] = {}
    for name, sets in contexts.items():
        bases = [o for o, base in contexts.items() if o != name and repeats(sets, base)]
        if len(bases) == 1:
            out[name] = bases[0]
    return {k: v for k, v in out.items() if v not in out}  # a cell is never a catch-up


def requirement(scenario: Scenario) -> tuple[str, str, str, float] | None:
    """(left signal, right signal, requirement name, bound) of the swept scenario's braking
    requirement, or None."""
    for entry in scenario.data.get("expect") or []:
        if not isinstance(entry, dict) or not isinstance(entry.get("stl"), str):
            continue
        match = _BRAKING.match(entry["stl"])
        name = entry.get("name")
        if match and isinstance(name, str) and float(match.group(2)) == float(match.group(4)):
            return match.group(1), match.group(3), name, float(match.group(2))
    return None


def braking(
    results: Path,
    scenario: Scenario,
    table: SweepTable,
    catchups: dict[tuple[Any, ...], tuple[Any, ...]],
    chosen: dict[tuple[Any, ...], tuple[Any, ...]],
    robust: tuple[Any, ...],
    leaf: str,
    band: dict[str, dict[str, float]],
    point: dict[str, Any],
    split: float = SPLIT,
) -> Braking | None:
    """The braking rule, or None (no braking requirement in the sweep, no catch-up of a
    switching cell, no swinging point, or the wrong braking not above the right one).

    ``table`` holds every cell's and catch-up's metric; ``catchups`` maps a catch-up's key to
    its cell's key, ``chosen`` each cell's key to its point; ``leaf``, ``band`` and ``point``
    are the damping rule's estimator, held-estimate band and point; ``split`` places the
    level between the right braking (0) and the wrong one (1)."""
    found = requirement(scenario)
    if found is None or not band:
        return None
    left, right_signal, name, bound = found
    buffers = scenario.world.buffers
    if left not in buffers or right_signal not in buffers:
        return None
    world, contexts = scenario.world, dict(scenario.data.get("sweep", {}).get("contexts", {}))
    try:
        hardest = read_table(
            results, f"robustness.{name}", world, contexts, set(table.context_axes)
        )
    except ConfigError:
        return None  # a sweep run before the requirement was added
    runs_of: dict[tuple[Any, ...], list[tuple[Any, ...]]] = {k: [k] for k in chosen}
    for key, cell in catchups.items():
        if cell in runs_of:
            runs_of[cell].append(key)

    def brakes(key: tuple[Any, ...], at: tuple[Any, ...]) -> float | None:
        here = hardest.stats.get(key, {}).get(at)
        return bound + here.mean if here is not None and here.stable else None  # kept negated

    # the cells whose rule sets a higher point than the robust one (the rule's target)
    switching = {k: p for k, p in chosen.items() if p != robust and _higher(p, robust)}
    if not any(len(runs_of[k]) > 1 for k in switching):
        return None  # no catch-up: the sweep never shows a right gain braking as it arrives
    right = []
    for key, at in switching.items():
        for run in runs_of[key]:
            value = brakes(run, at)
            if value is None:
                return None  # a chosen point without a measured braking: nothing to trust
            right.append(value)
    wrong = []
    for key, at in chosen.items():
        if at != robust:
            continue  # a cell keeping the robust point: a higher point there is wrong
        for run in runs_of[key]:
            by_point = table.stats.get(run, {})
            means = [s.mean for s in by_point.values() if s.stable]
            if not means:
                continue
            for high in set(switching.values()):
                here = by_point.get(high)
                swings = here is None or not here.stable or here.mean > (1 + SWINGS) * min(means)
                value = brakes(run, high)
                if swings and value is not None:
                    wrong.append(value)
    if not right or not wrong or min(wrong) <= max(right):
        return None
    hi, lo = max(right), min(wrong)
    level = round(hi + split * (lo - hi), 1)
    step = 1.0 / float(scenario.world.leaves[left.rpartition(".")[0]].freq)
    rule = {
        "when": {
            f"{leaf}.valid": {"below": 0.5},
            **{k: dict(v) for k, v in band.items()},
            left: {"below": -level},
            right_signal: {"below": -level},
        },
        "set": dict(point),
        "hold": step,
        "dwell": step,
        "label": f"damp, braking harder than a right gain ({hi:.0f} %; a wrong one {lo:.0f} %)",
    }
    return Braking(round(hi, 1), round(lo, 1), level, rule)


def _higher(point: tuple[Any, ...], than: tuple[Any, ...]) -> bool:
    """Every tuned value at least ``than``'s (numbers), and the two not equal."""
    pairs = list(zip(point, than, strict=True))
    numbers = all(isinstance(a, int | float) and isinstance(b, int | float) for a, b in pairs)
    return numbers and point != than and all(a >= b for a, b in pairs)
