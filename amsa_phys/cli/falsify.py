"""Falsification: search a box of context parameters for the worst case with CMA-ES."""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import resource
import sys
from pathlib import Path
from typing import Any

from ..atomic import write_atomic
from ..engine import interrupt
from ..errors import ConfigError, Interrupted, one_line
from ..falsify import counterexample
from ..falsify.advice import search_warnings
from ..falsify.objective import Objective, build_objective, requirement_objective
from ..falsify.outputs import describe_value, headline, write_results, write_worst
from ..falsify.resume import (
    check_same_search,
    check_trial_dirs,
    make_trial_dir,
    read_cached,
    read_trial,
)
from ..falsify.search import Progress, Settings, search
from ..falsify.space import Space, build_space
from ..falsify.trials import Trial, plot_trials, summarize, write_trial
from ..model.configure import duration_option
from ..model.scenario import Scenario, load_scenario
from ..model.schema import MAX_SEED
from ..model.wording import plural
from ..requirements.objective import requirement_of
from ..runs.rundir import default_run_dir, run_dir_for
from ..runs.suite import input_files
from ..runs.sweep import MAX_RUNS, unknown_metric
from .options import add_jobs
from .progress import bar as progress_bar

#: Most trials one command runs (each is a whole search).
MAX_TRIALS = 1000


def add_args(p: argparse.ArgumentParser) -> None:
    """Arguments of ``amsa-phys falsify``."""
    p.add_argument("scenario", help="scenario YAML file")
    p.add_argument(
        "--range",
        dest="ranges",
        action="append",
        default=[],
        metavar="Comp.param=lo:hi",
        help="a continuous axis of the box (repeatable); integer parameters are rounded",
    )
    p.add_argument(
        "--grid",
        action="append",
        default=[],
        metavar="Comp.param=a,b,...",
        help="a categorical axis (repeatable); values read as YAML",
    )
    p.add_argument("--budget", type=int, required=True, metavar="N", help="runs to spend")
    goal = p.add_mutually_exclusive_group()
    goal.add_argument(
        "--metric", help="maximise this metric (default rms_error); phase<i>.<metric> too"
    )
    goal.add_argument(
        "--expect",
        action="store_true",
        help="minimise the robustness of the scenario's expect: checks on metrics",
    )
    goal.add_argument(
        "--requirement",
        metavar="NAME",
        help="minimise the robustness of the scenario's STL requirement NAME (all: the least "
        "of every one); stops at the first falsifying run",
    )
    p.add_argument(
        "--search-on",
        action="store_true",
        help="with --requirement: spend the whole budget on the worst case after a violation",
    )
    p.add_argument(
        "--trials",
        type=int,
        default=1,
        metavar="N",
        help="repeat the search with seeds S..S+N-1; report the falsification rate and "
        "simulations to falsify (summary.json, trials.png)",
    )
    p.add_argument(
        "--resume",
        action="store_true",
        help="continue an interrupted search in --out DIR, running no finished run again",
    )
    p.add_argument("--seed", type=int, default=1, help="the search's seed (default 1)")
    add_jobs(p)
    p.add_argument(
        "--executor",
        choices=("batch", "local", "dask"),
        default="batch",
        help="where each generation runs: batch (default), local, dask (needs --scheduler)",
    )
    p.add_argument("--scheduler", metavar="ADDR", help="Dask scheduler address (tcp://...)")
    p.add_argument("--duration", type=float, metavar="S", help="override the duration")
    p.add_argument("--out", metavar="DIR", help="output (default runs/<scenario>-falsify-...)")
    p.add_argument("--force", action="store_true", help="replace an existing --out directory")


def check_seed(seed: int, trials: int) -> None:
    """Seeds are 0..2**63-1 everywhere; N trials use S..S+N-1."""
    if trials < 1 or trials > MAX_TRIALS:
        raise ConfigError(f"must be in 1..{MAX_TRIALS}", key="--trials")
    if not 0 <= seed <= MAX_SEED - (trials - 1):
        top = MAX_SEED - (trials - 1)
        raise ConfigError(
            f"must be an integer from 0 to {top}"
            + (" (2**63 - 1)" if trials == 1 else f" (2**63 - 1 less the {trials - 1} more trials)")
            + f", got {seed}",
            key="--seed",
        )


def _objective(
    args: argparse.Namespace, scenario: Scenario, n_phases: int
) -> tuple[Objective, list[str]]:
    if args.requirement is not None:
        return requirement_objective(list(scenario.expect), args.requirement, "--requirement"), []
    if args.metric is not None and requirement_of(args.metric) is None:
        why = unknown_metric(args.metric, n_phases)
        if why is not None:
            raise ConfigError(why, key="--metric")
    return build_objective(list(scenario.expect), args.metric, args.expect, n_phases)


def run(args: argparse.Namespace) -> int:
    """Search; write results.csv, worst.yaml, convergence.png; exit 1 on a violation."""
    check_seed(args.seed, args.trials)
    if args.resume and not args.out:
        raise ConfigError("--resume continues the search in --out DIR: give it", key="--resume")
    scenario = load_scenario(args.scenario)
    if scenario.ros2:  # a user's ROS 2 node answers one run at a time, each run in turn
        args.executor, args.jobs = "local", 1
    if args.budget < 1 or args.budget > MAX_RUNS:
        raise ConfigError(f"must be in 1..{MAX_RUNS:,}", key="--budget")
    if args.jobs < 1:
        raise ConfigError("must be at least 1", key="--jobs")
    if args.executor == "dask" and not args.scheduler:
        raise ConfigError("the Dask executor needs --scheduler ADDR", key="--executor")
    if args.duration is not None:
        duration_option(args.duration)
    space = build_space(scenario, args.ranges, args.grid)
    end = args.duration if args.duration is not None else float(scenario.duration)
    n_phases = len(scenario.timeline.phases_before(end))
    objective, warnings = _objective(args, scenario, n_phases)
    warnings += search_warnings(scenario, objective, space, end, args.search_on)
    for warning in warnings:
        print(one_line(f"warning: {warning}"), file=sys.stderr)
    name = Path(args.scenario).stem
    out = Path(args.out) if args.out else default_run_dir(f"{name}-falsify")
    if args.resume:
        if out.is_symlink():  # as a new --out (check_output_dir): never written through
            raise ConfigError(
                "is a symbolic link; give the real directory (amsa-phys does not write "
                "through links)",
                file=out,
                key="--out",
            )
        if not out.is_dir():
            raise ConfigError("not a directory to resume", file=out, key="--resume")
    # with --force the search is written beside an earlier one and renamed into place when it
    # ends (finished or interrupted: --resume continues it there); a killed search leaves the
    # earlier one whole
    place = (
        contextlib.nullcontext(out)
        if args.resume
        else run_dir_for(out, args.force, inputs=input_files(scenario), kind="falsify")
    )
    with place as work:
        return _search_into(work, out, args, scenario, objective, space, name)


def _search_into(
    work: Path,
    out: Path,
    args: argparse.Namespace,
    scenario: Scenario,
    objective: Objective,
    space: Space,
    name: str,
) -> int:
    """The search's trials, writing into ``work`` (``out`` itself, or staged beside it: the
    messages name ``out``)."""

    def shown(path: Path) -> Path:
        return out / path.relative_to(work)

    record = {
        "scenario": str(Path(args.scenario).resolve()),
        "ranges": args.ranges,
        "grids": args.grid,
        "budget": args.budget,
        "seed": args.seed,
        "trials": args.trials,
        "objective": objective.label,
        "requirements": list(objective.requirements),
        "stop_at_violation": objective.falsifies and not args.search_on,
        "duration": args.duration,
    }
    check_same_search(work / "falsify.json", record, args.resume)
    places = (
        [work] if args.trials == 1 else [work / f"trial-{k + 1:03d}" for k in range(args.trials)]
    )
    check_trial_dirs(places)  # before any trial writes: no link is ever written through
    finished = [  # every record judged before a trial runs again
        read_trial(here / "trial.json", args.seed + k, args.budget) if args.resume else None
        for k, here in enumerate(places)
    ]
    cached = [  # and every unfinished trial's rows: a damaged file refused before any runs
        read_cached(here / "results.csv", args.budget) if args.resume and done is None else None
        for here, done in zip(places, finished, strict=True)
    ]
    trials: list[Trial] = []
    violated = False
    for k, (here, done, rows) in enumerate(zip(places, finished, cached, strict=True)):
        if done is not None:
            trials.append(done)
            violated = violated or done.falsified
            if args.trials == 1:  # nothing left to run: say what the finished search found
                found = (
                    f"falsified after {done.simulations} simulations"
                    if done.falsified and done.simulations is not None
                    else "no violation"
                )
                print(
                    one_line(
                        f"already finished: {done.runs} runs, {found}; results in {shown(here)} "
                        "(nothing run again)"
                    )
                )
            continue
        make_trial_dir(here)
        settings = Settings(
            Path(args.scenario).resolve(),
            args.budget,
            args.seed + k,
            scenario.seed,
            args.duration,
            args.executor,
            args.jobs,
            args.scheduler,
            stop_at_violation=objective.falsifies and not args.search_on,
        )
        trial, found = _one_search(
            args, settings, objective, space, scenario, name, here, k, shown(here), rows
        )
        trials.append(trial)
        violated = violated or found
    summary = summarize(trials, args.budget, objective.label)
    write_atomic(work / "summary.json", json.dumps(summary, indent=1) + "\n")
    if args.trials > 1:
        plot_trials(summary, work / "trials.png", one_line(name))
        rate = summary["falsification_rate"]
        line = f"falsified {summary['falsified']} of {len(trials)} trials ({rate:.0%})"
        if summary["mean_simulations"] is not None:
            line += (
                f", {summary['mean_simulations']:.1f} simulations on average to the first "
                f"violation (median {summary['median_simulations']:g})"
            )
        least = summary["robustness_not_falsified"]["min"]
        if least is not None:
            line += f"; least {objective.label} reached when not falsified {least:.6g}"
        print(one_line(f"{line}; summary in {out / 'summary.json'}"))
    return 1 if violated else 0


def _counterexample(
    settings: Settings,
    objective: Objective,
    space: Space,
    scenario: Scenario,
    progress: Progress,
    name: str,
    out: Path,
) -> str:
    """worst.yaml as the falsifying context closest to nominal (``falsify/counterexample``),
    its run in counterexample/, counterexample.png; what to add to the printed line."""
    keys = [d.key for d in space.dims]
    nom = counterexample.nominal(space, scenario)
    found = counterexample.minimise(space, objective, settings, progress, nom)
    if found is None:
        return ""
    row, verdict, point = found
    row = {**row, **dict(point)}
    gap = counterexample.distance(point, nom, space)
    what = ", ".join(f"{k}={v}" for k, v in point)
    text = f"closest falsifying context to nominal: {what} ({verdict.why}; {gap:.3g} box widths)"
    write_worst(
        row, keys, settings, f"{text}\nreplay: amsa-phys run worst.yaml", out / "worst.yaml"
    )
    run_dir = counterexample.replay(settings, point, out / "counterexample")
    req = objective.requirements[0]
    metrics = json.loads((run_dir / "metrics.json").read_text()).get("requirements") or {}
    if len(objective.requirements) > 1:  # the requirement this context breaks most
        req = min(
            objective.requirements,
            key=lambda n: (metrics.get(n) or {}).get("robustness") or math.inf,
        )
    entry = metrics.get(req) or {}
    counterexample.plot(run_dir, req, out / "counterexample.png", one_line(name))
    when = ""
    if entry.get("instant") is not None:
        when = f", broken at t={entry['instant']:g} s by {entry.get('atom', '?')}"
    return f"; {text}{when}"


def _cpu() -> float:
    """CPU seconds of this process and its finished children (worker pools)."""
    me = resource.getrusage(resource.RUSAGE_SELF)
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    return me.ru_utime + me.ru_stime + kids.ru_utime + kids.ru_stime


def _one_search(
    args: argparse.Namespace,
    settings: Settings,
    objective: Objective,
    space: Space,
    scenario: Scenario,
    name: str,
    out: Path,
    k: int,
    shown: Path,
    cached: dict[int, dict[str, Any]] | None,
) -> tuple[Trial, bool]:
    """One trial: search, write its files in ``out`` (``shown``: its name in messages, where
    ``out`` is staged); (its outcome, whether it violated)."""
    keys = [d.key for d in space.dims]
    progress = Progress()
    if cached is not None:  # --resume: the rows read before the first trial ran
        progress.cached = cached
    interrupted = False
    cpu0 = _cpu()
    bar = progress_bar(args.budget, "run" if args.trials == 1 else f"trial {k + 1} run")

    def said(generation: int) -> None:  # a line per generation, above the progress bar
        w = progress.worst()
        worst = describe_value(progress.verdicts[w].value) if w is not None else "none"
        type(bar).write(
            f"generation {generation} done: {plural(len(progress.rows), 'run')}, worst "
            f"{objective.label} {worst}",
            file=sys.stderr,
        )

    progress.on_generation = said
    try:
        with (
            interrupt.sigterm_as_ctrl_c(),
            interrupt.deferred(),
            bar,
        ):
            for _ in search(space, objective, settings, progress):
                bar.update(1)
            interrupt.check()
    except KeyboardInterrupt:
        interrupted = True
    worst = progress.worst()
    line = (
        headline(progress, worst, keys, objective, args.budget)
        if worst is not None
        else f"no run of {len(progress.rows)} could be judged"
    )
    first = progress.first_violation()
    if first is not None and settings.stop_at_violation:
        line += f"; first violation at run {first} ({plural(first + 1, 'simulation')})"
    with interrupt.sigterm_as_ctrl_c(), interrupt.deferred():
        write_results(progress.rows, keys, out / "results.csv")
        raw = "worst.yaml"
        if worst is not None and objective.falsifies and first is not None and not interrupted:
            raw = "worst_raw.yaml"
            line += _counterexample(settings, objective, space, scenario, progress, name, out)
        if worst is not None:
            write_worst(
                progress.rows[worst],
                keys,
                settings,
                f"{line}\nreplay: amsa-phys run {raw}",
                out / raw,
            )
        _plot(progress, objective, name, out, interrupted, args.budget)
        late = interrupt.requested()
    print(f"{line}; results in {shown}")
    if progress.exhausted and len(progress.rows) < args.budget:
        print(
            one_line(
                f"the search stopped after {len(progress.rows)} of its {args.budget} runs: "
                "every point of the box was run (its axes are all --grid lists), or the "
                "optimizer proposed only points already run"
            ),
            file=sys.stderr,
        )
    if args.resume:
        print(f"resumed: {progress.reused} finished runs taken from results.csv", file=sys.stderr)
    failed = [r for r in progress.rows if r["error"]]
    for r in failed[:5]:
        print(one_line(f"run {r['run']}: {r['error']}"), file=sys.stderr)
    if interrupted or late:
        raise Interrupted(
            f"falsify interrupted; {len(progress.rows)} finished rows kept in {shown} "
            "(--resume continues)"
        )
    trial = Trial.of(settings.seed, progress, _cpu() - cpu0)
    write_trial(trial, out / "trial.json")
    return trial, worst is not None and progress.verdicts[worst].violated


def _plot(
    progress: Progress, objective: Objective, name: str, out: Path, interrupted: bool, budget: int
) -> None:
    """convergence.png (matplotlib is imported only now that the rows are in)."""
    from ..plots.convergence import plot_convergence

    rows = sorted(zip(progress.rows, progress.verdicts, strict=True), key=lambda rv: rv[0]["run"])
    bound = 0.0 if objective.metric is None else None
    if objective.metric is not None and len(objective.checks) == 1:
        e = objective.checks[0]
        bound = e.below if e.below is not None else e.above
    title = f"{name}: worst {objective.label} so far"
    if interrupted:
        title += f"; interrupted: {len(rows)} of {budget} runs"
    maximise = objective.metric is not None
    worst = math.inf if maximise else -math.inf
    values = [  # a point no run could take has no value; a fault is the worst there is
        None if v.score == math.inf else worst if v.score == -math.inf else v.value for _, v in rows
    ]
    plot_convergence(
        values,
        [r["generation"] for r, _ in rows],
        objective.label,
        maximise,
        out / "convergence.png",
        one_line(title),
        threshold=bound,
    )
