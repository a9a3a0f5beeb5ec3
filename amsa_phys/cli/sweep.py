"""Exhaustive exploration: a parameter grid × seeds in parallel, on this machine or Dask."""

from __future__ import annotations

import argparse
import csv
import io
import os
import sys
from collections.abc import Iterator
from fractions import Fraction
from pathlib import Path
from typing import Any

from ..atomic import write_atomic
from ..engine import interrupt
from ..errors import ConfigError, Interrupted, one_line
from ..model.configure import duration_option
from ..model.scenario import load_scenario
from ..model.wording import plural
from ..model.yamlio import load_yaml
from ..runs.batched import iter_batched, iter_dask_batched, plan_units
from ..runs.rundir import default_run_dir, run_dir_for
from ..runs.suite import input_files
from ..runs.sweep import (
    Axis,
    Job,
    SweepPlan,
    check_axes,
    check_size,
    deterministic_points,
    iter_local,
    iter_ros2_lanes,
    parse_grid,
    parse_range,
    timeline_overlaps,
    unknown_sweep_metric,
)
from ..runs.sweepbest import best_line
from ..stl.requirement import cut_windows
from .options import add_jobs
from .progress import bar as progress_bar


def add_args(p: argparse.ArgumentParser) -> None:
    """Arguments of ``amsa-phys sweep``."""
    p.add_argument("scenario", help="scenario YAML file (its sweep: section gives defaults)")
    p.add_argument(
        "--grid",
        action="append",
        default=[],
        metavar="Comp.param=v1,v2,...",
        help="a grid axis (repeatable); values read as YAML",
    )
    p.add_argument(
        "--range",
        dest="ranges",
        action="append",
        default=[],
        metavar="Comp.param=start:stop:n",
        help="n evenly spaced values",
    )
    p.add_argument("--seeds", type=int, help="seeds per grid point (default 1)")
    add_jobs(p)
    p.set_defaults(jobs=None)  # all cores unless given; a ros2: scenario's runs: one domain
    p.add_argument(
        "--executor",
        choices=("batch", "local", "dask"),
        default="batch",
        help="where the runs go: batch (default): batches of runs as columns of one "
        "simulation, on -j local worker processes; local: one run per process; dask: "
        "batches on an existing Dask cluster (needs --scheduler and the cluster extra)",
    )
    p.add_argument(
        "--batch-size",
        type=int,
        metavar="N",
        help="runs per batch (default: two batches per worker, at most 250)",
    )
    p.add_argument("--scheduler", metavar="ADDR", help="Dask scheduler address (tcp://...)")
    p.add_argument("--metric", help="metric for summary.png (default rms_error)")
    p.add_argument("--duration", type=float, metavar="S", help="override the duration")
    p.add_argument("--out", metavar="DIR", help="output (default runs/<scenario>-sweep-...)")
    p.add_argument("--force", action="store_true", help="replace an existing --out directory")
    p.add_argument(
        "--keep-runs", action="store_true", help="also write each run's directory under DIR/runs/"
    )


def build_plan(args: argparse.Namespace) -> SweepPlan:
    """Merge the scenario's ``sweep:`` section with the command line (which wins)."""
    scenario = load_scenario(args.scenario)
    args.ros2_serial = bool(scenario.ros2)
    if args.duration is not None:  # refused once, before a job is built (not in every row)
        duration_option(args.duration)
    doc = load_yaml(args.scenario)
    section = scenario.data.get("sweep", {})
    axes: list[Axis] = []
    contexts: dict[str, dict[str, Any]] = dict(section.get("contexts", {}))
    if contexts:
        axes.append(Axis("context", tuple(contexts)))
    cli_axes = [parse_grid(g) for g in args.grid] + [parse_range(r) for r in args.ranges]
    cli_keys = {a.key for a in cli_axes}
    for key, values in section.get("grid", {}).items():
        if key not in cli_keys:
            axes.append(Axis(key, tuple(values)))
    axes += cli_axes
    if not axes:
        raise ConfigError("nothing to sweep: give --grid/--range or a sweep: section", key="sweep")
    seeds = args.seeds if args.seeds is not None else int(section.get("seeds", 1))
    if seeds < 1:
        raise ConfigError("must be at least 1", key="--seeds")
    check_size(axes, seeds)  # before a single value is judged or a job built
    try:
        check_axes([a for a in axes if a.key != "context"], scenario)
    except ConfigError as exc:
        if "grid" in section and exc.key and exc.key.removeprefix("--grid ") in section["grid"]:
            raise doc.error(
                ("sweep", "grid", exc.key.removeprefix("--grid ")), exc.message
            ) from None
        raise
    from ..model.scenario import resolve_change

    for name, sets in contexts.items():
        for key, value in sets.items():
            try:
                resolve_change(key, value, scenario.world)
            except ValueError as exc:
                raise doc.error(("sweep", "contexts", name, key), str(exc)) from None
    metric = args.metric or section.get("metric", "rms_error")
    end = args.duration if args.duration is not None else scenario.duration
    why = unknown_sweep_metric(
        metric,
        len(scenario.timeline.phases_before(end)),
        [str(e.name) for e in scenario.expect if e.stl is not None],
    )
    if why is not None:
        if args.metric is None:
            raise doc.error(("sweep", "metric"), why)
        raise ConfigError(why, key="--metric")
    swept = [a.key for a in axes if a.key != "context"]
    swept += [k for sets in contexts.values() for k in sets]
    plan = SweepPlan(
        Path(args.scenario).resolve(),
        axes,
        seeds,
        scenario.seed,
        contexts,
        metric,
        args.duration,
        inputs=tuple(input_files(scenario)),
        warnings=(
            *timeline_overlaps(swept, scenario, Fraction(str(end))),
            *(
                f"the requirement {name} reads until t={until:g} s: runs of {float(end):g} s "
                f"cannot judge it, so results.csv's robustness.{name} stays empty"
                for name, until in cut_windows(scenario.expect, float(end))
            ),
        ),
    )
    if seeds > 1 and (same := same_seeds_warning(plan, scenario)):
        plan.warnings += (same,)
    return plan


def same_seeds_warning(plan: SweepPlan, scenario: Any) -> str | None:
    """A warning if, at some grid points, nothing random runs: their seeds are copies."""
    same = deterministic_points(plan, scenario)
    if not same:
        return None
    total = 1
    for a in plan.axes:
        total *= len(a.values)
    example = ", ".join(f"{k}={v}" for k, v in same[0])
    return (
        f"nothing random at {len(same)} of {total} grid points (e.g. {example}: no "
        f"sensor noise or loss, no random leader), so their {plan.seeds} seeds give identical "
        "runs"
    )


def run(args: argparse.Namespace) -> int:
    """Run the sweep; results.csv and summary.png; Ctrl-C keeps every finished row."""
    args.jobs_given = args.jobs is not None
    if args.jobs is None:
        args.jobs = os.cpu_count() or 1
    plan = build_plan(args)
    if args.executor == "dask" and not args.scheduler:
        raise ConfigError("the Dask executor needs --scheduler ADDR", key="--executor")
    if args.jobs < 1:
        raise ConfigError("must be at least 1", key="--jobs")
    if args.batch_size is not None and args.batch_size < 1:
        raise ConfigError("must be at least 1", key="--batch-size")
    if args.batch_size is not None and args.executor == "local":
        raise ConfigError(
            "sets the runs of a batch; --executor local runs one per process", key="--batch-size"
        )
    if args.ros2_serial:  # before --out is made: a refused domain leaves nothing behind
        check_ros2_lanes(min(args.jobs if args.jobs_given else 1, plan.size))
    name = Path(args.scenario).stem
    out = Path(args.out) if args.out else default_run_dir(f"{name}-sweep")
    # with --force the sweep is written beside an earlier one and renamed into place when it
    # ends (finished or interrupted): a killed sweep leaves the earlier one whole
    with run_dir_for(out, args.force, inputs=plan.inputs, kind="sweep") as work:
        return _sweep_into(work, out, args, plan, name)


def _sweep_into(work: Path, out: Path, args: argparse.Namespace, plan: Any, name: str) -> int:
    """Run the sweep, writing into ``work`` (``out`` itself, or staged beside it: the messages
    name ``out``)."""
    # warned only once the sweep will run: a refused --out or option is the one line printed
    for warning in plan.warnings:
        print(f"warning: {warning}", file=sys.stderr)
    from ..adapt.sweepdir import write_sweep_scenario  # what `adapt SWEEPDIR` reads back

    recorded = load_scenario(args.scenario)
    full = float(recorded.duration)
    cut = plan.duration is not None and float(plan.duration) < full
    write_sweep_scenario(
        work,
        recorded,
        {"contexts": plan.contexts, "metric": plan.metric, "seeds": plan.seeds},
    )
    if args.keep_runs:
        plan.keep_dir = str((work / "runs").resolve())
    jobs = plan.jobs()
    rows: list[dict[str, Any]] = []
    source = rows_from(jobs, args)
    interrupted = False
    try:
        # Ctrl-C is raised between completions, never inside concurrent.futures or Dask
        with (
            interrupt.sigterm_as_ctrl_c(),
            interrupt.deferred(),
            progress_bar(len(jobs), "run") as bar,
        ):
            for row in source:
                rows.append(row)
                bar.update(1)
            interrupt.check()  # a Ctrl-C noted after the last row still counts
    except KeyboardInterrupt:
        interrupted = True
    keys = [a.key for a in plan.axes]
    # a signal while the files are written is noted, not raised inside matplotlib: the
    # results and the picture are finished first (a SIGTERM in plot_summary killed the
    # process with -15 and no summary.png)
    with interrupt.sigterm_as_ctrl_c(), interrupt.deferred():
        write_results(rows, keys, work / "results.csv")
        drawn = any(not r["error"] for r in rows)  # nothing to draw: no picture saying so
        if drawn:
            _summary(rows, keys, plan, work, name, interrupted, len(jobs), full if cut else None)
        late = interrupt.requested()
    failed = [r for r in rows if r["error"]]
    print(
        one_line(
            f"{len(rows)} of {plural(len(jobs), 'run')} done ({len(failed)} failed); "
            f"results in {out}"
        )
    )
    best = best_line(rows, keys, plan.metric)
    if best is not None:  # the summary's star, in the terminal
        print(one_line(best))
    for r in failed[:5]:
        print(one_line(f"run {r['run']}: {r['error']}"), file=sys.stderr)
    if interrupted:
        raise Interrupted(f"sweep interrupted; {plural(len(rows), 'finished row')} kept in {out}")
    if late:
        raise Interrupted(
            f"interrupted after the sweep's last run; its outputs are complete in {out}"
        )
    return 0


def _summary(
    rows: list[dict[str, Any]],
    keys: list[str],
    plan: Any,
    out: Path,
    name: str,
    interrupted: bool,
    planned: int,
    full: float | None = None,
) -> None:
    """``summary.png`` of the completed rows (only called when there is one); ``full``: the
    scenario's length where ``--duration`` cut the runs shorter (the title says so)."""
    from ..plots.summary import cut_note, plot_summary  # matplotlib: once the rows are in

    plot_summary(
        rows,
        keys,
        plan.metric,
        out / "summary.png",
        one_line(
            f"{name}: {plan.metric} ({plan.seeds} seed{'s' if plan.seeds > 1 else ''})"
            + (f"; {cut_note(float(plan.duration), full)}" if full is not None else "")
            + (f"; interrupted: {len(rows)} of {planned} runs" if interrupted else "")
        ),
    )


def check_ros2_lanes(lanes: int) -> None:
    """Refuse a ``ROS_DOMAIN_ID`` the sweep's ROS 2 lanes cannot use: not a domain (int() of
    it was a traceback), or one whose ``lanes - 1`` followers pass the last domain."""
    if lanes <= 1:
        return
    from ..ros.ros2.env import MAX_DOMAIN_ID, domain_problem

    value = os.environ.get("ROS_DOMAIN_ID")
    problem = domain_problem(value)
    if problem:
        raise ConfigError(problem, key="sweep")
    base = int(value or 0)
    if base + lanes - 1 > MAX_DOMAIN_ID:
        raise ConfigError(
            f"-j {lanes} runs in ROS_DOMAIN_ID={base} and the {lanes - 1} after it, past "
            f"{MAX_DOMAIN_ID}: set a lower ROS_DOMAIN_ID or fewer jobs",
            key="sweep",
        )


def rows_from(jobs: list[Job], args: argparse.Namespace) -> Iterator[dict[str, Any]]:
    """Result rows as they come from the chosen executor (batched unless ``local``)."""
    if getattr(args, "ros2_serial", False):  # a user's ROS 2 node answers one run at a time
        # -j N: N domains from ROS_DOMAIN_ID, a copy of the node in each; without -j, one
        return iter_ros2_lanes(jobs, min(args.jobs if args.jobs_given else 1, len(jobs)))
    if args.executor == "local":
        return iter_local(jobs, min(args.jobs, len(jobs)))
    units, notes = plan_units(jobs, args.jobs, args.batch_size)
    for note in notes:
        print(one_line(f"note: {note}"), file=sys.stderr)
    if args.executor == "dask":
        return iter_dask_batched(units, args.scheduler)
    return iter_batched(units, min(args.jobs, len(units)), iter_local)


def write_results(rows: list[dict[str, Any]], axes: list[str], path: Path) -> None:
    """results.csv sorted by run index, so it never depends on completion order."""
    rows = sorted(rows, key=lambda r: r["run"])
    fields = ["run", *axes, "seed_index", "seed", "error"]
    for r in rows:
        for k in r:
            if k not in fields:
                fields.append(k)
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=fields, lineterminator="\n")
    writer.writeheader()
    for r in rows:
        writer.writerow({k: ("" if r.get(k) is None else r.get(k)) for k in fields})
    write_atomic(path, buf.getvalue())
