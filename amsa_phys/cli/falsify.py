"""Falsification: search a box of context parameters for the worst case with CMA-ES."""

from __future__ import annotations

import argparse
import math
import sys
from fractions import Fraction
from pathlib import Path

from ..engine import interrupt
from ..errors import ConfigError, Interrupted, one_line
from ..falsify.objective import Objective, build_objective
from ..falsify.outputs import describe_value, headline, write_results, write_worst
from ..falsify.search import Progress, Settings, search
from ..falsify.space import build_space
from ..model.configure import duration_option
from ..model.scenario import load_scenario
from ..runs.rundir import default_run_dir, prepare_run_dir
from ..runs.suite import input_files
from ..runs.sweep import MAX_RUNS, timeline_overlaps, unknown_metric
from .options import add_jobs
from .progress import bar as progress_bar


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


def run(args: argparse.Namespace) -> int:
    """Search; write results.csv, worst.yaml, convergence.png; exit 1 on a violation."""
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
    n_phases = sum(1 for p in scenario.phases if p.at < end)
    if args.metric is not None:
        why = unknown_metric(args.metric, n_phases)
        if why is not None:
            raise ConfigError(why, key="--metric")
    objective, warnings = build_objective(scenario.expect, args.metric, args.expect, n_phases)
    keys = [d.key for d in space.dims]
    warnings += timeline_overlaps(keys, scenario, Fraction(str(end)))
    for warning in warnings:
        print(one_line(f"warning: {warning}"), file=sys.stderr)
    name = Path(args.scenario).stem
    out = Path(args.out) if args.out else default_run_dir(f"{name}-falsify")
    prepare_run_dir(out, args.force, inputs=input_files(scenario))
    settings = Settings(
        Path(args.scenario).resolve(),
        args.budget,
        args.seed,
        scenario.seed,
        args.duration,
        args.executor,
        args.jobs,
        args.scheduler,
    )
    progress = Progress()
    interrupted = False

    bar = progress_bar(args.budget, "run")

    def said(generation: int) -> None:  # a line per generation, above the progress bar
        k = progress.worst()
        worst = describe_value(progress.verdicts[k].value) if k is not None else "none"
        type(bar).write(
            f"generation {generation} done: {len(progress.rows)} runs, worst "
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
    with interrupt.sigterm_as_ctrl_c(), interrupt.deferred():
        write_results(progress.rows, keys, out / "results.csv")
        if worst is not None:
            write_worst(
                progress.rows[worst],
                keys,
                settings,
                f"{line}\nreplay: amsa-phys run worst.yaml",
                out / "worst.yaml",
            )
        _plot(progress, objective, name, out, interrupted, args.budget)
        late = interrupt.requested()
    print(f"{line}; results in {out}")
    failed = [r for r in progress.rows if r["error"]]
    for r in failed[:5]:
        print(one_line(f"run {r['run']}: {r['error']}"), file=sys.stderr)
    if interrupted or late:
        raise Interrupted(f"falsify interrupted; {len(progress.rows)} finished rows kept in {out}")
    return 1 if worst is not None and progress.verdicts[worst].violated else 0


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
