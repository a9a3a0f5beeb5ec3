"""From a context sweep's ``results.csv`` to ``adapt:`` rules.

A *cell* is one context of the sweep: a value of its ``context`` axis (a named parameter set)
and/or of a grid axis on a parameter some estimator watches (``links.py``). Every other
axis is *tuned*. For each cell the tuned values with the lowest seed-mean metric are the
cell's best. The cell's context parameters (the sweep's values over the scenario's own)
give the level each estimator output settles to there (``Estimates.expected``: about
0.01 x ``motorCoef`` for ``MotorMonitor.delivered``, 0.01 x ``lostDataGPS`` for
``GPSLossMonitor.lossRate``, 0 straight / 0.5 random for ``LeaderMonitor.turning``). A rule
per cell then conditions each output that differs between cells on the band around the
cell's level: above the midpoint to the next lower level, below the midpoint to the next
higher one. Cells are reported, not guessed, when an estimator cannot place them (a context
parameter no estimator watches, a value its mapping does not know) or when two cells with
different best values settle to the same levels.
"""

from __future__ import annotations

import statistics
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..errors import ConfigError
from ..model.scenario import Scenario
from ..runs.sweep import read_results
from .links import Watch, watches


@dataclass
class Cell:
    """One context of the sweep: its parameters, best tuned values and estimator levels."""

    name: str
    context: dict[str, Any]
    best: dict[str, Any] = field(default_factory=dict)
    score: float = float("nan")
    runs: int = 0
    levels: dict[str, float] = field(default_factory=dict)


@dataclass
class Derivation:
    """What ``amsa-phys adapt`` found: rules, the cells behind them, what it could not place."""

    metric: str
    tuned: list[str]
    cells: list[Cell]
    rules: list[dict[str, Any]]
    unplaced: list[str]
    watches: list[Watch]


def derive(
    results: Path, scenario: Scenario, metric: str = "rms_error", hold: float = 10.0
) -> Derivation:
    """Rules from the sweep in ``results`` (a results.csv) run on ``scenario``."""
    rows, axes = read_results(results)
    if rows and metric not in rows[0]:
        raise ConfigError(f"no metric column {metric!r} in the sweep", file=results)
    found = watches(scenario.world)
    watched = {w.key for w in found}
    contexts: dict[str, dict[str, Any]] = dict(scenario.data.get("sweep", {}).get("contexts", {}))
    if "context" in axes and not contexts:
        raise ConfigError(
            "the sweep has a context axis but the scenario given has no sweep.contexts; "
            "give the scenario the sweep ran",
            file=results,
        )
    context_axes = [a for a in axes if a == "context" or a in watched]
    tuned = [a for a in axes if a not in context_axes]
    if not tuned:
        raise ConfigError("no tuned axis: every axis is a context", file=results)
    if not context_axes:
        # one context only: there is nothing for a rule to tell apart (a Kv-only sweep)
        raise ConfigError(
            f"no context axis: the sweep's axes ({', '.join(axes)}) are all tuned; sweep a "
            "'context' axis (the scenario's sweep.contexts) or a parameter an estimator "
            "watches, so rules have contexts to tell apart",
            file=results,
        )
    base = _base_values(scenario)
    cells: dict[tuple[Any, ...], Cell] = {}
    scores: dict[tuple[Any, ...], dict[tuple[Any, ...], list[float]]] = {}
    for row in rows:
        key = tuple(row[a] for a in context_axes)
        if key not in cells:
            ctx = dict(base)
            name = []
            for a, v in zip(context_axes, key, strict=True):
                if a == "context":
                    if v not in contexts:
                        raise ConfigError(
                            f"context {v!r} is not in the scenario's sweep.contexts", file=results
                        )
                    ctx.update(contexts[v])
                else:
                    ctx[a] = v
                name.append(str(v) if a == "context" else f"{a}={v}")
            cells[key] = Cell(", ".join(name), ctx)
        value = row[metric]
        if row["error"] or value is None:
            continue
        scores.setdefault(key, {}).setdefault(tuple(row[a] for a in tuned), []).append(value)
    for key, cell in cells.items():
        by_point = scores.get(key, {})
        if not by_point:
            continue
        best = min(by_point, key=lambda p: (statistics.fmean(by_point[p]), p))
        cell.best = dict(zip(tuned, best, strict=True))
        cell.score = statistics.fmean(by_point[best])
        cell.runs = sum(len(v) for v in by_point.values())
    unplaced = _place(list(cells.values()), found, watched)
    placed = [
        c
        for c in cells.values()
        if c.best and c.levels is not None and c.name not in _names(unplaced)
    ]
    rules = _rules(placed, hold)
    return Derivation(metric, tuned, list(cells.values()), rules, unplaced, found)


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


def _rules(cells: list[Cell], hold: float) -> list[dict[str, Any]]:
    """One rule per placed cell (cells at the same levels with the same best share one)."""
    signals = sorted({s for c in cells for s in c.levels})
    levels = {s: sorted({c.levels[s] for c in cells if s in c.levels}) for s in signals}
    rules: list[dict[str, Any]] = []
    seen: dict[tuple[Any, ...], dict[str, Any]] = {}
    for cell in cells:
        when: dict[str, dict[str, float]] = {}
        for s in signals:
            ls = levels[s]
            if len(ls) < 2 or s not in cell.levels:
                continue
            i = ls.index(cell.levels[s])
            bound: dict[str, float] = {}
            if i > 0:
                bound["above"] = round((ls[i - 1] + ls[i]) / 2, 6)
            if i < len(ls) - 1:
                bound["below"] = round((ls[i] + ls[i + 1]) / 2, 6)
            when[s] = bound
        if not when:
            continue
        key = (
            tuple(sorted((k, tuple(sorted(v.items()))) for k, v in when.items())),
            tuple(sorted(cell.best.items())),
        )
        if key in seen:
            seen[key]["label"] += f", {cell.name}"
            continue
        whole = int(hold) if float(hold).is_integer() else hold
        rule = {"when": when, "set": dict(cell.best), "hold": whole, "label": cell.name}
        seen[key] = rule
        rules.append(rule)
    return rules
