"""Robust tuning: the controller parameters best in the worst case over a context set."""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from typing import Any

from ..errors import ConfigError, one_line
from ..model.changes import resolve_change
from ..model.scenario import Scenario, load_scenario
from ..model.wording import plural
from ..runs.sweep import MAX_RUNS
from ..tune.contexts import Sequence, box, sequences
from ..tune.evaluate import evaluate
from ..tune.robust import tail
from ..tune.search import minimise

#: Most evaluations ``--budget`` may ask for (each is contexts x seeds runs).
MAX_BUDGET = 10_000


def add_args(p: argparse.ArgumentParser) -> None:
    """Arguments of ``amsa-phys tune``."""
    p.add_argument("scenario", help="the scenario to tune (its world, quality and duration)")
    p.add_argument(
        "--range",
        action="append",
        default=[],
        dest="ranges",
        metavar="Comp.param=lo:hi",
        help="a parameter to tune and its bounds (repeat for several)",
    )
    p.add_argument(
        "--contexts",
        metavar="SWEEPDIR",
        help="the contexts of a sweep directory (default: the scenario's sweep.contexts)",
    )
    p.add_argument(
        "--box",
        type=int,
        default=0,
        metavar="K",
        help="instead of the named contexts, K contexts (1..1000) drawn from the box they "
        "span; 0 (the default): the named contexts themselves",
    )
    p.add_argument(
        "--seeds", type=int, default=2, metavar="N", help="seeds per context (default 2)"
    )
    p.add_argument("--budget", type=int, default=12, metavar="N", help="evaluations (default 12)")
    p.add_argument(
        "--measure",
        choices=("worst", "cvar"),
        default="worst",
        help="tail measure over contexts x seeds: worst (default) or cvar",
    )
    p.add_argument(
        "--alpha", type=float, default=0.2, help="cvar's share of worst cases (default 0.2)"
    )
    p.add_argument(
        "--metric",
        default="rms_error",
        help="metric (lower is better) or robustness.NAME (higher is better)",
    )
    p.add_argument("--duration", type=float, metavar="S", help="seconds per run (the scenario's)")


def _ranges(texts: list[str], scenario: Scenario) -> list[tuple[str, float, float, bool]]:
    out = []
    for text in texts:
        key, sep, spec = text.partition("=")
        lo_s, colon, hi_s = spec.partition(":")
        try:
            if not (sep and colon):
                raise ValueError
            lo, hi = float(lo_s), float(hi_s)
            if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
                raise ValueError
        except ValueError:
            raise ConfigError(
                f"expected Comp.param=lo:hi with lo < hi, got {one_line(text)!r}", key="--range"
            ) from None
        key = key.strip()
        if any(key == k for k, *_ in out):
            raise ConfigError(f"{one_line(key)} appears twice", key="--range")
        try:
            for v in (lo, hi):
                change = resolve_change(key, v, scenario.world)
        except ValueError as exc:
            raise ConfigError(str(exc), key=f"--range {one_line(key)}") from None
        out.append((key, lo, hi, isinstance(change.value, int)))
    if not out:
        raise ConfigError("give at least one parameter to tune", key="--range")
    return out


def _check_metric(metric: str, scenario: Scenario, duration: float) -> None:
    """Refuse, before any run, a ``--metric`` no run would give a value for: an unknown
    metric or requirement, or a requirement whose windows runs of ``duration`` cut (every
    evaluation would score the worst there is, and the budget would be spent for nothing)."""
    from fractions import Fraction

    from ..requirements.objective import requirement_of, unknown_objective
    from ..stl.requirement import cut_windows

    names = [str(e.name) for e in scenario.expect if e.stl is not None]
    phases = len(scenario.timeline.phases_before(Fraction(str(duration))))
    why = unknown_objective(metric, phases, names)
    if why is not None:
        raise ConfigError(why, key="--metric")
    req = requirement_of(metric)
    for name, until in cut_windows(scenario.expect, duration, [req] if req else []):
        raise ConfigError(
            f"the requirement {name} reads until t={until:g} s: runs of {duration:g} s cannot "
            "judge it (give a longer --duration)",
            key="--metric",
        )


def _contexts(args: argparse.Namespace, scenario: Scenario) -> dict[str, dict[str, Any]]:
    if args.contexts:
        from ..adapt.sweepdir import read_sweep_scenario

        recorded = read_sweep_scenario(
            Path(args.contexts), "give the contexts in the scenario's sweep: contexts instead"
        )
        contexts = dict(recorded.data.get("sweep", {}).get("contexts", {}))
    else:
        contexts = dict(scenario.data.get("sweep", {}).get("contexts", {}))
    if not contexts:
        raise ConfigError(
            "no contexts: give --contexts SWEEPDIR or a scenario with sweep.contexts",
            key="--contexts",
        )
    for name, sets in contexts.items():
        for key, value in sets.items():
            try:
                resolve_change(key, value, scenario.world)
            except ValueError as exc:
                raise ConfigError(
                    f"context {one_line(name)}: {one_line(key)}: {exc}", key="--contexts"
                ) from None
    return contexts


def run(args: argparse.Namespace) -> int:
    """Search the ranges; print every evaluation and the robust choice."""
    if not 1 <= args.budget <= MAX_BUDGET:
        raise ConfigError(f"must be 1..{MAX_BUDGET}, got {args.budget}", key="--budget")
    if not 1 <= args.seeds <= 1000:
        raise ConfigError(f"must be 1..1000, got {args.seeds}", key="--seeds")
    if not 0 <= args.box <= 1000:
        raise ConfigError(f"must be 0..1000, got {args.box}", key="--box")
    if not 0 < args.alpha <= 1:
        raise ConfigError(f"must be in (0, 1], got {args.alpha}", key="--alpha")
    scenario = load_scenario(args.scenario)
    ranges = _ranges(args.ranges, scenario)
    contexts = _contexts(args, scenario)
    duration = float(scenario.duration) if args.duration is None else args.duration
    if not (0 < duration <= 1_000_000 and math.isfinite(duration)):
        raise ConfigError(f"must be a positive number of seconds, got {duration}", key="--duration")
    _check_metric(args.metric, scenario, duration)
    _check_runs(args.budget, args.box or len(contexts), args.seeds)
    if args.box:
        cases = sequences(box(scenario, contexts), args.box, duration, seed=7, segments=(1, 1))
    else:
        cases = [Sequence(((0.0, dict(sets)),)) for sets in contexts.values()]
    keys = [r[0] for r in ranges]
    sense = "higher" if args.metric.startswith("robustness.") else "lower"
    print(
        one_line(
            f"tuning {', '.join(keys)} over {_over(len(cases), bool(args.box))} x "
            f"{plural(args.seeds, 'seed')} ({args.measure} of {args.metric}, {sense} is "
            f"better), budget {plural(args.budget, 'evaluation')}"
        )
    )

    def objective(point: tuple[float, ...]) -> float:
        settings = dict(zip(keys, point, strict=True))
        values = [
            evaluate(scenario, case, settings, seed, args.metric, duration)
            for case in cases
            for seed in range(1, args.seeds + 1)
        ]
        score = tail(values, args.measure, args.alpha)
        shown = ", ".join(f"{k}={v:g}" for k, v in settings.items())
        print(one_line(f"  {shown}: {args.measure} {_show(score, args.metric)}"), flush=True)
        return score

    found = minimise(
        objective,
        [(lo, hi) for _, lo, hi, _ in ranges],
        args.budget,
        integer=[r[3] for r in ranges],
    )
    best = found.best
    if not math.isfinite(best.score):
        print("no evaluated point finished every context and seed", file=sys.stderr)
        return 1
    shown = ", ".join(f"{k}={v:g}" for k, v in zip(keys, best.values, strict=True))
    print(
        one_line(
            f"robust choice: {shown} ({args.measure} {_show(best.score, args.metric)} over "
            f"{plural(len(cases), 'context')} x {plural(args.seeds, 'seed')}; "
            f"{plural(len(found.trials), 'evaluation')})"
        )
    )
    return 0


def _check_runs(budget: int, contexts: int, seeds: int) -> None:
    """Refuse a search of more runs than a sweep may have (:data:`MAX_RUNS`), before any.

    Each bound alone is modest, their product is not: ``--budget 10000 --box 1000 --seeds
    1000`` asked for 10^10 runs (centuries), and a sweep directory's named contexts are
    as many as its author wrote."""
    runs = budget * contexts * seeds
    if runs > MAX_RUNS:
        raise ConfigError(
            f"{budget:,} evaluations x {plural(contexts, 'context')} x {plural(seeds, 'seed')} "
            f"is {runs:,} runs; a search has at most {MAX_RUNS:,}, as a sweep",
            key="--budget",
        )


def _over(n: int, drawn: bool) -> str:
    """What the contexts are: drawn from the box (``--box K``) or the named ones."""
    return (
        plural(n, "context drawn from their box", "contexts drawn from their box")
        if drawn
        else plural(n, "named context")
    )


def _show(score: float, metric: str) -> str:
    value = -score if metric.startswith("robustness.") else score
    return f"{value:.4g}"
