"""From a context sweep's ``results.csv`` to ``adapt:`` rules that hold on unseen contexts.

A *cell* is one context of the sweep: a value of its ``context`` axis (a named parameter set)
and/or of a grid axis on a parameter some estimator watches (``links.py``). Every other
axis is *tuned*; a *point* is one combination of tuned values.

Rules are only worth writing if switching beats keeping one good point, so three numbers
come first. The **robust point** is the point whose worst cell is least bad (the least
worst-case seed mean, as ``amsa-phys tune --measure worst`` minimises over the same
contexts; ``robust=`` gives tune's answer instead); it is what the robot runs when the
estimators are unsure. Each cell's **safe best** is its lowest seed-mean point whose grid neighbours
(one step along each tuned axis) all finished and are at most ``margin`` worse: a gain one
step below instability is never chosen, since the estimate that picks it is never exact
(the robust point instead, when no safe point beats it there). Two more cautions, for
the same reason: of the safe points within ``near`` of the lowest, the one fewest grid steps
from the robust point is the best, and a cell keeps the robust point unless its best beats
it there by ``cell_gain`` (a switch costs a transient and a detection delay).
The **oracle** is each cell's safe best, switched at the true instants; when its mean over
the cells gains less than ``min_gain`` over the robust point's mean, there is nothing for
adaptation to win and no rules are written (:attr:`Derivation.refused`).

The cell's context parameters give the level each estimator output settles to there
(``Estimates.expected``). A rule per cell conditions each output that differs between
cells on a band around the cell's level: from the midpoint to the next level, less a
``gap`` share of the distance on each side, so an estimate between two bands fires
neither rule and the gain in force stays (hysteresis); each rule must hold for ``hold``
seconds, and two switches are at least ``hold`` apart (dwell). Before them, one rule per
estimator with a ``valid`` output sets the robust point once it has been 0 (unsure) for
``fallback_hold`` seconds, but never within the estimator's own ``window`` seconds of a
switch (the rule's ``dwell``: a switch's transient stays in the window that long, and a
gain that is right for the context may blind the estimate while it settles), and the cell
rules require every such estimator to be sure. In a sweep that
measures braking, a context that repeats another one with parameters no estimator watches
(the follower started behind) is that cell's *catch-up*, not a cell: only the braking rule
reads it (``braking.py``). Cells
are reported, not guessed, when an estimator cannot place them (a context parameter no
estimator watches, a value its mapping does not know) or when two cells with different
best values settle to the same levels.
"""

from __future__ import annotations

import math
import statistics
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..control.estimators.watches import Watch, watches
from ..errors import ConfigError
from ..model.scenario import Scenario
from ..requirements.objective import higher_is_better
from .braking import Braking, braking, catch_ups
from .braking import requirement as braking_requirement
from .cellrules import cell_rules as rules_of_cells
from .cellrules import whole
from .damping import FACTOR, STEPS, Damping, damping
from .damping import guarded as _guarded
from .grid import lowest, robust_point, safe_best
from .recovery import recovery
from .swing import FACTOR as SWING_FACTOR
from .swing import Swing, swing
from .table import SweepTable, read_table

#: Default safety margin: a best point's grid neighbours may be at most this much worse.
MARGIN = 0.5
#: Default least gain of the oracle schedule over the robust point worth adapting for.
MIN_GAIN = 0.05
#: A safe point at most this much worse than a cell's lowest safe mean counts as level with
#: it, and the one nearest the robust point among those is the cell's best. A held-out level
#: between two cells sits between their best gains, and the estimate that places it is never
#: exact: of two gains level in the cell, the one nearer the robust gain is the safer guess
#: (on the shipped box: Kv 0.3 rather than 0.35 for worn motors, 0.6 rather than 0.7 for very
#: worn ones, each 0.4-0.5 % worse in its cell, the next point 10-13 % worse).
NEAR = 0.05
#: A cell leaves the robust point only for a point at least this much better there. Every
#: switch costs a transient and a detection delay, and a gain that wins little in its cell
#: loses more where the estimate misplaces the context: on the shipped box the nominal
#: cell's Kv 0.15 (9.5 % better there) and the tired random leader's 0.3 (8 %) lost 2-10 %
#: to the robust gain on held-out sequences of motors at 74-92 %; the cells adaptation is
#: for gain 27-63 %.
CELL_GAIN = 0.15
#: Seconds an estimator must stay unsure before the robust point is set (None: the rules'
#: hold). A longer wait keeps a switch that blinds an estimator for a while (a high gain on
#: very worn motors makes the loop reverse now and then) but leaves a wrong one in force
#: longer: on the shipped box 60 s gained 20-25 % on very worn motors and lost 5-12 % on
#: two other held-out sequences (``adapt --validate``), so the default stays the hold.
FALLBACK_HOLD: float | None = None
#: Seconds after a switch before a fallback may fire (None: each estimator's ``window``).
#: Switching to a high gain with the follower far behind makes the loop reverse for a few
#: seconds; the motor estimate turns unsure until that leaves its window, and a fallback
#: after the hold alone undid every switch to very worn motors' gain within ~22 s
#: (``adapt --validate`` on the shipped box: 8 % gained there instead of 22-30 %).
FALLBACK_DWELL: float | None = None
#: A damping rule fires above this multiple of the fastest path speed the sweep saw under a
#: chosen point (0: no damping rule); see ``damping.py``.
DAMP = FACTOR
#: A swing rule fires above this multiple of the largest swing the sweep saw under a chosen
#: point (0: no swing rule); see ``swing.py``. Only a sweep that measures the swing gets one.
SWING = SWING_FACTOR


@dataclass
class Cell:
    """One context of the sweep: its parameters, best tuned values and estimator levels."""

    name: str
    context: dict[str, Any]
    best: dict[str, Any] = field(default_factory=dict)
    score: float = float("nan")
    runs: int = 0
    levels: dict[str, float] = field(default_factory=dict)
    #: the lowest mean, when it is not the cell's best (``why`` says why not)
    unsafe: tuple[dict[str, Any], float] | None = None
    why: str = ""
    robust_score: float = float("nan")


@dataclass
class Derivation:
    """What ``amsa-phys adapt`` found: rules, the cells behind them, what it could not place."""

    metric: str
    tuned: list[str]
    cells: list[Cell]
    rules: list[dict[str, Any]]
    unplaced: list[str]
    watches: list[Watch]
    robust: dict[str, Any] = field(default_factory=dict)
    robust_mean: float = float("nan")
    oracle_mean: float = float("nan")
    refused: str | None = None
    #: the damping rule, when the sweep measured the path speed (``damping.py``)
    damping: Damping | None = None
    #: the recovery rule, when the motor estimate has a recent share (``recovery.py``)
    recovery: dict[str, Any] | None = None
    #: the braking rule, when the sweep measured braking and has catch-ups (``braking.py``)
    braking: Braking | None = None
    #: the catch-up contexts (a cell started away from its reference): name -> its cell
    catch_ups: dict[str, str] = field(default_factory=dict)
    #: the swing supervisor, when the sweep measured the swing (``swing.py``)
    swing: Swing | None = None

    @property
    def gain(self) -> float:
        """What the oracle schedule gains over the robust point (0.1: 10 % lower metric, or
        10 % more robustness: a ``robustness.NAME`` objective is kept negated)."""
        if not (self.robust_mean != 0 and math.isfinite(self.robust_mean)):
            return 0.0
        return (self.robust_mean - self.oracle_mean) / abs(self.robust_mean)


def derive(
    results: Path,
    scenario: Scenario,
    metric: str = "rms_error",
    hold: float = 10.0,
    margin: float = MARGIN,
    min_gain: float = MIN_GAIN,
    robust: dict[str, Any] | None = None,
    fallback_hold: float | None = FALLBACK_HOLD,
    fallback_dwell: float | None = FALLBACK_DWELL,
    near: float = NEAR,
    cell_gain: float = CELL_GAIN,
    damp: float = DAMP,
    damp_steps: int = STEPS,
    guard: bool = True,
    swing_factor: float = SWING,
    swing_holds: bool = True,
) -> Derivation:
    """Rules from the sweep in ``results`` (a results.csv) run on ``scenario``; ``robust``
    is the fixed choice to fall back on (default: the sweep's least worst-case point)."""
    found = watches(scenario.world)
    watched = {w.key for w in found}
    contexts: dict[str, dict[str, Any]] = dict(scenario.data.get("sweep", {}).get("contexts", {}))
    table = read_table(results, metric, scenario.world, contexts, watched)
    if not table.rows:
        raise ConfigError("no runs in the sweep", file=results)
    if not table.tuned:
        raise ConfigError("no tuned axis: every axis is a context", file=results)
    if not table.context_axes:
        # one context only: there is nothing for a rule to tell apart (a Kv-only sweep)
        raise ConfigError(
            f"no context axis: the sweep's axes ({', '.join(table.axes)}) are all tuned; sweep "
            "a 'context' axis (the scenario's sweep.contexts) or a parameter an estimator "
            "watches, so rules have contexts to tell apart",
            file=results,
        )
    # catch-ups are cells started away from their reference: read by the braking rule only
    # (only in a sweep that measures braking, their one reader: elsewhere such a context is
    # a cell the estimators cannot place, and is reported as one)
    reads = "context" in table.context_axes and braking_requirement(scenario) is not None
    repeats = catch_ups(contexts, watched) if reads else {}
    at = table.context_axes.index("context") if repeats else 0
    every = dict(table.stats)
    catchup_keys = {
        key: (*key[:at], repeats[key[at]], *key[at + 1 :])
        for key in every
        if repeats and key[at] in repeats
    }
    table.stats = {k: v for k, v in every.items() if k not in catchup_keys}
    base = _base_values(scenario)
    cells: dict[tuple[Any, ...], Cell] = {}
    for key in table.stats:
        ctx = dict(base)
        name = []
        for a, v in zip(table.context_axes, key, strict=True):
            if a == "context":
                ctx.update(contexts[v])
            else:
                ctx[a] = v
            name.append(str(v) if a == "context" else f"{a}={v}")
        cells[key] = Cell(", ".join(name), ctx)
    given = robust
    robust = robust_point(table, margin)
    if given is not None:
        if sorted(given) != sorted(table.tuned):
            raise ConfigError(
                f"must set exactly the tuned axes ({', '.join(table.tuned)})",
                key="--robust",
            )
        robust = tuple(given[k] for k in table.tuned)
        if not all(robust in by for by in table.stats.values()):
            raise ConfigError(
                "that point is not on the sweep's grid in every context (the "
                "oracle and the margin compare grid points)",
                key="--robust",
            )
    for key, cell in cells.items():
        by_point = table.stats[key]
        cell.runs = sum(s.count + s.failed for s in by_point.values())
        safest = safe_best(table, key, margin)
        best = safe_best(table, key, margin, robust, near)
        if (
            robust is not None
            and robust in by_point
            and (
                best is None
                or by_point[best].mean > (1.0 - cell_gain) * by_point[robust].mean
                or by_point[robust].mean <= by_point[best].mean
            )
        ):
            best = robust  # never a choice worse than the fallback, nor one barely better
        if best is None:
            continue
        cell.best = dict(zip(table.tuned, best, strict=True))
        cell.score = by_point[best].mean
        low = lowest(by_point)
        if low is not None and low != best:
            cell.unsafe = (dict(zip(table.tuned, low, strict=True)), by_point[low].mean)
            if low != safest:
                cell.why = "a neighbour is unstable or far worse"
            elif best == robust:
                cell.why = f"less than {100 * cell_gain:g} % better than the robust point"
            else:
                cell.why = f"level within {100 * near:g} % and nearer the robust point"
        if robust is not None and robust in by_point:
            cell.robust_score = by_point[robust].mean
    derivation = Derivation(metric, table.tuned, list(cells.values()), [], [], found)
    derivation.catch_ups = dict(repeats)
    if robust is None:
        derivation.refused = (
            "no grid point finished in every context: there is no fixed choice to fall back "
            "on, so no rules are written"
        )
        return derivation
    derivation.robust = dict(zip(table.tuned, robust, strict=True))
    scored = [c for c in cells.values() if c.best and math.isfinite(c.robust_score)]
    derivation.robust_mean = statistics.fmean(c.robust_score for c in scored)
    derivation.oracle_mean = statistics.fmean(c.score for c in scored)
    if derivation.gain < min_gain:
        derivation.refused = (
            f"not worth adapting: switching to each context's best would "
            f"{'raise' if higher_is_better(metric) else 'lower'} the mean "
            f"{metric} by {100 * derivation.gain:.1f} % over the robust choice "
            f"({_show(derivation.robust)}), less than {100 * min_gain:g} %; run that "
            "fixed choice instead"
        )
        return derivation
    derivation.unplaced = _place(list(cells.values()), found, watched)
    placed = [
        c
        for c in cells.values()
        if c.best and c.levels is not None and c.name not in _names(derivation.unplaced)
    ]
    # cells the estimators cannot tell apart run the robust point (a rule still brings the
    # gain back to it when the context returns there)
    groups: dict[tuple[tuple[str, float], ...], list[Cell]] = {}
    for c in cells.values():
        if c.best and c.levels and "looks to the estimators" in _why(derivation.unplaced, c.name):
            groups.setdefault(tuple(sorted(c.levels.items())), []).append(c)
    for group in groups.values():
        placed.append(
            Cell(
                ", ".join(c.name for c in group) + " (alike: robust)",
                {},
                dict(derivation.robust),
                levels=dict(group[0].levels),
            )
        )
    wait = hold if fallback_hold is None else fallback_hold
    fallbacks = _fallbacks(scenario, found, placed, derivation.robust, wait, fallback_dwell)
    sure = {signal: {"above": 0.5} for r in fallbacks for signal in r["when"]}
    cell_rules = [{**r, "when": {**r["when"], **sure}} for r in rules_of_cells(placed, hold)]
    chosen = {key: tuple(c.best[k] for k in table.tuned) for key, c in cells.items() if c.best}
    if damp > 0:
        used = {s for c in placed for s in c.levels}
        derivation.damping = damping(
            results, scenario, table, chosen, robust, used, damp, damp_steps
        )
    if derivation.damping is not None:
        # the estimator's fallback waits for the swing to end: the robust gain restarts it
        valid = f"{derivation.damping.leaf}.valid"
        below = {f"{derivation.damping.leaf}.pathSpeed": {"below": derivation.damping.release}}
        fallbacks = [
            {**r, "when": {**r["when"], **below}} if valid in r["when"] else r for r in fallbacks
        ]
        band = _switched_band(cell_rules, derivation.robust, derivation.damping.leaf, found)
        derivation.damping.rule["when"].update(band)
        fallbacks.insert(0, derivation.damping.rule)
        derivation.braking = braking(
            results,
            scenario,
            SweepTable(table.axes, table.context_axes, table.tuned, every, table.rows),
            catchup_keys,
            chosen,
            robust,
            derivation.damping.leaf,
            band,
            derivation.damping.point,
        )
        if derivation.braking is not None:
            fallbacks.insert(0, derivation.braking.rule)
        if guard:
            fallbacks = _guarded(fallbacks, valid, band)
    derivation.swing = swing(results, scenario, table, chosen, robust, swing_factor)
    if derivation.swing is not None:
        cell_rules, fallbacks = derivation.swing.supervise(
            cell_rules, fallbacks, derivation.robust, derivation.damping, swing_holds
        )
    for w in found:
        if derivation.recovery is None and w.signal in {s for c in placed for s in c.levels}:
            derivation.recovery = recovery(scenario, cell_rules, derivation.robust, w.signal)
    if derivation.recovery is not None:
        fallbacks.insert(0, derivation.recovery)
    derivation.rules = fallbacks + cell_rules
    return derivation


def _switched_band(
    rules: list[dict[str, Any]], robust: dict[str, Any], leaf: str, found: list[Watch]
) -> dict[str, dict[str, float]]:
    """The band of ``leaf``'s estimates in which some cell rule sets a point other than the
    robust one: a swing starts only where such a point was set, so the damping rule reads
    the held estimate there and nowhere else (a robust gain's own swing on healthy motors
    is not damped by a lower one: it only falls behind)."""
    out: dict[str, dict[str, float]] = {}
    away = [r for r in rules if r["set"] != robust]
    for signal in (w.signal for w in found if w.signal.rpartition(".")[0] == leaf):
        bands = [r["when"].get(signal) for r in away]
        if not bands or any(b is None for b in bands):
            continue
        band: dict[str, float] = {}
        if all("below" in b for b in bands):
            band["below"] = max(b["below"] for b in bands)
        if all("above" in b for b in bands):
            band["above"] = min(b["above"] for b in bands)
        if band:
            out[signal] = band
    return out


def _why(unplaced: Sequence[str], name: str) -> str:
    return " ".join(u for u in unplaced if u.split(":", 1)[0] == name)


def _show(values: dict[str, Any]) -> str:
    return ", ".join(f"{k}={v}" for k, v in values.items())


def _fallbacks(
    scenario: Scenario,
    found: list[Watch],
    placed: list[Cell],
    robust: dict[str, Any],
    hold: float,
    dwell: float | None = None,
) -> list[dict[str, Any]]:
    """One rule per estimator the cell rules read that says when it is unsure (``valid``),
    firing after ``hold`` s of it but not within ``dwell`` s of a switch (None: the
    estimator's ``window`` parameter; a dwell at or below the hold is left out)."""
    used = {s for c in placed for s in c.levels}
    out = []
    for w in found:
        leaf = w.signal.rpartition(".")[0]
        valid = f"{leaf}.valid"
        if w.signal not in used or valid not in scenario.world.buffers:
            continue
        rule: dict[str, Any] = {
            "when": {valid: {"below": 0.5}},
            "set": dict(robust),
            "hold": whole(hold),
        }
        wait = dwell if dwell is not None else _window(scenario, leaf)
        if wait is not None and wait > hold:
            rule["dwell"] = whole(wait)
        rule["label"] = f"robust, {leaf} unsure"
        out.append(rule)
    return out


def _window(scenario: Scenario, leaf: str) -> float | None:
    """The estimator's ``window`` in seconds, if it has one (how long a transient stays in)."""
    value = scenario.world.leaves[leaf].params.get("window")
    for change in scenario.timeline.initial:
        if change.key == f"{leaf}.window":
            value = change.value
    return float(value) if isinstance(value, int | float) and not isinstance(value, bool) else None


def _names(unplaced: Sequence[str]) -> set[str]:
    return {u.split(":", 1)[0] for u in unplaced}


def _base_values(scenario: Scenario) -> dict[str, Any]:
    """Every Leaf parameter at t = 0 (world values, then the scenario's ``set``)."""
    out = {
        f"{path}.{k}": v
        for path, leaf in scenario.world.leaves.items()
        for k, v in leaf.params.items()
    }
    out.update({c.key: c.value for c in scenario.timeline.initial})
    return out


def _place(cells: list[Cell], found: list[Watch], watched: set[str]) -> list[str]:
    """Give each cell its estimator levels; return why some cells cannot be told apart."""
    problems: list[str] = []
    varying = sorted(
        {
            k
            for c in cells
            for k, v in c.context.items()
            if any(d.context.get(k) != v for d in cells)
        }
    )
    blind = [k for k in varying if k not in watched]
    for cell in cells:
        if not cell.best:
            problems.append(f"{cell.name}: no run of this cell has a value of the metric")
            continue
        for w in found:
            if w.key not in varying:
                continue
            level = w.estimates.expected(cell.context[w.key])
            if level is None:
                problems.append(
                    f"{cell.name}: {w.signal} has no known level for {w.key}={cell.context[w.key]}"
                )
                break
            cell.levels[w.signal] = level
    bad = _names(problems)
    groups: dict[tuple[tuple[str, float], ...], list[Cell]] = {}
    for cell in cells:
        if cell.name not in bad:
            groups.setdefault(tuple(sorted(cell.levels.items())), []).append(cell)
    for group in groups.values():
        if len(group) > 1 and len({tuple(sorted(c.best.items())) for c in group}) > 1:
            differ = [k for k in blind if len({c.context.get(k) for c in group}) > 1]
            why = (
                f" (they differ in {', '.join(differ)}, which no estimator watches)"
                if differ
                else ""
            )
            names = ", ".join(c.name for c in group)
            for c in group:
                problems.append(
                    f"{c.name}: looks to the estimators like another cell with other best values "
                    f"[{names}]{why}"
                )
    return problems
