"""Redraw a run's plots from its trace and metrics, or a sweep's summary from results.csv."""

from __future__ import annotations

import argparse
import math
import sys
from fractions import Fraction
from pathlib import Path
from typing import Any

from ..errors import AmsaError, ConfigError, one_line
from ..model.scenario import load_scenario
from ..model.template import Kind
from ..runs.plotjob import draw_run_plots, plot_context
from ..runs.rundata import read_run, read_world
from ..runs.rundir import check_output
from ..runs.runfiles import read_metrics, trace_header
from ..runs.sweep import read_results, unknown_metric


def add_args(p: argparse.ArgumentParser) -> None:
    """Arguments of ``amsa-phys plot``."""
    p.add_argument(
        "rundir",
        nargs="*",
        help="a run directory (`amsa-phys run`) or a sweep directory (`amsa-phys sweep`); "
        "with --paper: the runs to draw, as run directories or scenario files (run in memory; "
        "default scenarios/paper_fig5_kv*.yaml or scenarios/paper_fig6.yaml)",
    )
    p.add_argument(
        "--paper",
        choices=("fig5", "fig6", "fig6-sensed", "fig5-start", "fig7"),
        help="the paper's Fig. 5 or Fig. 6 redrawn from the runs, beside the paper's numbers "
        "(-o default: paper_fig5.png / paper_fig6.png); fig6-sensed: Fig. 6 at 0/10/50/90 %% "
        "GPS loss, with the distance sensed from GPS beside the paper's true-distance wiring "
        "(scenarios/paper_fig6_sensed.yaml and paper_fig6.yaml); fig5-start: Fig. 5's "
        "maxima and rms errors against the initial gap between the rovers; fig7: the adaptive "
        "run of scenarios/adaptive.yaml against every fixed Kv",
    )
    p.add_argument(
        "-o",
        "--output",
        help="distance plot PNG (default RUNDIR/distance.png; the trajectory plot "
        "goes next to it as <name>-trajectory.png, or RUNDIR/trajectory.png); "
        "for a sweep: the summary PNG (default DIR/summary.png)",
    )
    p.add_argument(
        "--metric",
        help="sweep only: the metric to plot, overall or phase<i>.<metric> (default rms_error)",
    )


def run(args: argparse.Namespace) -> int:
    """Draw the plot."""
    if args.paper:
        if args.metric is not None:
            raise ConfigError("only for a sweep directory (with results.csv)", key="--metric")
        return _plot_paper(args)
    if len(args.rundir) != 1:
        raise ConfigError(
            "expected one run or sweep directory (several only with --paper)", key="plot"
        )
    rundir = Path(args.rundir[0])
    if not rundir.is_dir():
        raise ConfigError(
            "no such directory" if not rundir.exists() else "not a directory", file=rundir
        )
    if (rundir / "results.csv").is_file() and not (rundir / "trace.csv").exists():
        return _plot_sweep(rundir, args)
    if args.metric is not None:
        raise ConfigError("only for a sweep directory (with results.csv)", key="--metric")
    for name in ("trace.csv", "metrics.json"):
        if not (rundir / name).is_file():
            raise ConfigError(
                f"not a run directory: {name} is missing (nor a sweep's: no results.csv)",
                file=rundir,
            )
    metrics = read_metrics(rundir / "metrics.json")
    out = Path(args.output) if args.output else rundir / "distance.png"
    traj = out.with_name(out.stem + "-trajectory.png") if args.output else rundir / "trajectory.png"
    for target in (out, traj):
        check_output(target, "--output")
    written = draw_run_plots(rundir / "trace.csv", metrics, out, traj, _world_of(rundir))
    print(one_line("wrote " + " and ".join(str(p) for p in written)))
    if out not in written:
        print(f"no {out.name}: the scenario has no quality: section (no signal to plot)")
    return 0


def _world_of(rundir: Path) -> dict[str, Any] | None:
    """The arena and GPS links from the run's resolved scenario.yaml, read as data (a
    module it names is not imported: :mod:`amsa_phys.runs.rundata`); None if it is absent
    or unreadable: the paths are then drawn without the static world."""
    path = rundir / "scenario.yaml"
    if not path.is_file():
        return None
    try:
        return plot_context(read_world(path, trace_header(rundir / "trace.csv")))  # type: ignore[arg-type]
    except (AmsaError, OSError) as exc:
        print(one_line(f"warning: {exc}; the paths are drawn without the world"), file=sys.stderr)
        return None


def _plot_sweep(sweepdir: Path, args: argparse.Namespace) -> int:
    """summary.png again, for any metric column: no need to rerun the sweep to see another."""
    from ..plots.summary import nevers, plot_summary  # matplotlib: once the rows are read

    rows, axes = read_results(sweepdir / "results.csv")
    metric = args.metric or "rms_error"
    phases = sum(1 for key in rows[0] if key.endswith(".rms_error")) if rows else 0
    why = unknown_metric(metric, phases)
    if why is not None:
        raise ConfigError(why, key="--metric")
    seeds = len({r["seed_index"] for r in rows})
    out = Path(args.output) if args.output else sweepdir / "summary.png"
    check_output(out, "--output")
    name = _sweep_scenario(sweepdir)
    title = one_line(f"{name}: {metric} ({seeds} seed{'s' if seeds != 1 else ''})")
    plot_summary(rows, axes, metric, out, title, scenario=name)
    print(one_line(f"wrote {out}"))
    failed = sum(1 for r in rows if r.get("error"))
    empty = sum(1 for r in rows if not r.get("error") and r.get(metric) is None)
    never = len(nevers(rows, metric))
    if never:
        print(f"{never} of {len(rows)} runs never reached a {metric}: drawn as 'never'")
        empty -= never
    if failed or empty:
        print(
            f"left out {failed + empty} of {len(rows)} runs: {empty} with no {metric} value,"
            f" {failed} failed"
        )
    return 0


def _sweep_scenario(sweepdir: Path) -> str:
    """The scenario a sweep ran, for the title: recorded in its ``summary.png``, else in a
    kept run's metrics (``--keep-runs``), else (an older sweep) the folder's name."""
    from ..plots.summary import scenario_of

    name = scenario_of(sweepdir / "summary.png")
    if name:
        return name
    for metrics in sorted((sweepdir / "runs").glob("*/metrics.json"))[:1]:
        try:
            found = read_metrics(metrics).get("scenario")  # judged, at most 64 MiB read
        except (AmsaError, OSError):
            found = None
        if isinstance(found, str) and found:
            return found
    return sweepdir.name


def _plot_paper(args: argparse.Namespace) -> int:
    """``--paper fig5|fig6``: run (or read) the paper's scenarios and draw the figure."""
    if args.paper == "fig7":
        from .plot_fig7 import plot_fig7

        return plot_fig7(args)
    from ..plots import paper  # matplotlib: only once the runs are in

    if args.paper in ("fig6-sensed", "fig5-start"):
        from .paperplots import plot_losses, plot_starts

        return plot_losses(args) if args.paper == "fig6-sensed" else plot_starts(args)
    sources = [Path(s) for s in args.rundir] or _paper_scenarios(args.paper)
    out = Path(args.output) if args.output else Path(f"paper_{args.paper}.png")
    check_output(out, "--output")
    runs = [_paper_run(src) for src in sources]
    if args.paper == "fig5":
        runs.sort(key=lambda r: -(r.kv if r.kv is not None else -1.0))
        paper.fig5(runs, out)
    else:
        if len(runs) != 1:
            raise ConfigError("Fig. 6 is one run (Kv 0.35, then 0.05)", key="--paper fig6")
        paper.fig6(runs[0], out)
    print(one_line(f"wrote {out} ({len(runs)} run{'s' if len(runs) != 1 else ''})"))
    return 0


def _paper_scenarios(figure: str) -> list[Path]:
    """The shipped scenarios of a figure, found under ./scenarios."""
    pattern = {"fig5": "paper_fig5_kv*.yaml", "fig6-sensed": "paper_fig6_sensed.yaml"}.get(
        figure, "paper_fig6.yaml"
    )
    found = sorted(Path("scenarios").glob(pattern))
    if not found:
        raise ConfigError(
            f"no scenarios/{pattern} here: run it from the project's folder or name the "
            "scenarios or run directories",
            key=f"--paper {figure}",
        )
    return found


def _paper_run(source: Path, overrides: list[str] | None = None) -> Any:
    """A :class:`~amsa_phys.plots.paper.PaperRun` from a run directory or a scenario file
    (run with ``overrides``, ``--set`` texts)."""
    from ..plots.distance import read_trace
    from ..plots.paper import PaperRun

    if source.is_dir():  # data only: nothing the run directory names is imported
        run = read_run(source)
        columns, data = read_trace(run.trace)
        assert run.world is not None  # scenario.yaml is required
        assert run.resolved is not None
        kv, later = _run_kv(run, source)
        name = one_line(str(run.resolved.get("name", source.name)))
        label = name if kv is None else _kv_label(name, kv, later)
        metrics = run.metrics
    else:
        from ..engine import interrupt
        from ..engine.tracemem import TraceMemory
        from ..runs.single import execute

        scenario = load_scenario(source, overrides)
        kv, label = _kv(scenario), _label(source, scenario)
        memory = TraceMemory(list(scenario.world.buffers))
        with interrupt.deferred():
            ended = execute(scenario, memory, progress=False)
        if ended.error is not None:
            raise ended.error
        metrics = ended.metrics
        columns, data = ["t", *memory.columns], memory.matrix()
    q = metrics.get("quality")
    if not q or q["signal"] not in columns:
        raise ConfigError("the run has no quality signal to draw", file=source)
    t, d = data[:, 0], data[:, columns.index(q["signal"])]
    return PaperRun(label, kv, t, d, metrics)


def _kv(scenario: Any) -> float | None:
    """The controller's Kv at t = 0 (the world's, or the scenario's set:), if it has one."""
    for path, leaf in scenario.world.leaves.items():
        if "Kv" in leaf.params and leaf.kind.value == "controller":
            value = leaf.params["Kv"]
            for change in scenario.timeline.initial:
                if change.leaf == path and change.param == "Kv":
                    value = change.value
            return float(value)
    return None


def _kv_changes(scenario: Any) -> list[tuple[float, float]]:
    """(time, Kv) of every later change of the controller's Kv (phases and steps)."""
    path = next(
        (
            p
            for p, leaf in scenario.world.leaves.items()
            if "Kv" in leaf.params and leaf.kind.value == "controller"
        ),
        None,
    )
    out = []
    for point in scenario.timeline.points():
        for change in point.changes:
            if change.leaf == path and change.param == "Kv":
                out.append((float(point.at), float(change.value)))
    return out


def _label(source: Path, scenario: Any) -> str:
    """The panel's title: the scenario and every Kv it shows (``Kv = 0.35, then 0.05 from
    100 s``), not only the first."""
    kv = _kv(scenario)
    if kv is None:
        return one_line(str(scenario.name))
    return _kv_label(one_line(str(scenario.name)), kv, _kv_changes(scenario))


def _kv_label(name: str, kv: float, later: list[tuple[float, float]]) -> str:
    after = "".join(f", then {value:g} from {at:g} s" for at, value in later)
    return one_line(f"{name}: Kv = {kv:g}{after}")


def _run_kv(run: Any, source: Path) -> tuple[float | None, list[tuple[float, float]]]:
    """A run directory's controller Kv at t = 0 and its later changes, from the resolved
    scenario as data (the world's value, its ``set:``, its ``timeline:``)."""
    path = next(
        (
            p
            for p, leaf in run.world.leaves.items()
            if "Kv" in leaf.params and leaf.kind == Kind.CONTROLLER
        ),
        None,
    )
    if path is None:
        return None, []
    key = f"{path}.Kv"
    where = source / "scenario.yaml"
    try:
        kv = float(run.world.leaves[path].params["Kv"])
        initial = run.resolved.get("set") or {}
        if isinstance(initial, dict) and key in initial:
            kv = float(initial[key])
        later = []
        for entry in run.resolved.get("timeline") or []:
            sets = entry.get("set") or {} if isinstance(entry, dict) else {}
            if key in sets:
                later.append((float(Fraction(str(entry["at"]))), float(sets[key])))
    except (TypeError, ValueError, KeyError, ZeroDivisionError, AttributeError):
        why = f"not a resolved scenario: {key} or its changes are not numbers"
        raise ConfigError(why, file=where) from None
    if not all(math.isfinite(v) for pair in [(kv, 0.0), *later] for v in pair):
        why = f"not a resolved scenario: {key} or its changes are not finite"
        raise ConfigError(why, file=where)
    return kv, later
