"""Redraw a run's plots from its trace and metrics, or a sweep's summary from results.csv."""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

from ..errors import AmsaError, ConfigError, one_line
from ..model.scenario import load_scenario
from ..runs.plotjob import draw_run_plots, plot_context
from ..runs.rundir import check_output
from ..runs.sweep import read_results, unknown_metric


def add_args(p: argparse.ArgumentParser) -> None:
    """Arguments of ``amsa-phys plot``."""
    p.add_argument(
        "rundir", help="a run directory (`amsa-phys run`) or a sweep directory (`amsa-phys sweep`)"
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
    rundir = Path(args.rundir)
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
    """The arena and GPS links from the run's resolved scenario.yaml (None if unreadable:
    the paths are then drawn without the static world)."""
    try:
        return plot_context(load_scenario(rundir / "scenario.yaml").world)
    except (AmsaError, OSError):
        return None


def _plot_sweep(sweepdir: Path, args: argparse.Namespace) -> int:
    """summary.png again, for any metric column: no need to rerun the sweep to see another."""
    from ..plots.summary import plot_summary  # matplotlib: only once the rows are read

    rows, axes = read_results(sweepdir / "results.csv")
    metric = args.metric or "rms_error"
    phases = sum(1 for key in rows[0] if key.endswith(".rms_error")) if rows else 0
    why = unknown_metric(metric, phases)
    if why is not None:
        raise ConfigError(why, key="--metric")
    seeds = len({r["seed_index"] for r in rows})
    out = Path(args.output) if args.output else sweepdir / "summary.png"
    check_output(out, "--output")
    title = one_line(f"{sweepdir.name}: {metric} ({seeds} seed{'s' if seeds != 1 else ''})")
    plot_summary(rows, axes, metric, out, title)
    print(one_line(f"wrote {out}"))
    failed = sum(1 for r in rows if r.get("error"))
    empty = sum(1 for r in rows if not r.get("error") and r.get(metric) is None)
    if failed or empty:
        print(
            f"left out {failed + empty} of {len(rows)} runs: {empty} with no {metric} value"
            f" (null: e.g. never settled), {failed} failed"
        )
    return 0


def read_metrics(path: Path) -> dict[str, Any]:
    """A run's ``metrics.json``, checked for what the plots read (one line if it is not)."""
    try:
        metrics = json.loads(path.read_bytes())
    except json.JSONDecodeError as exc:
        raise ConfigError(f"invalid JSON: {exc.msg}", file=path, line=exc.lineno) from None
    except UnicodeDecodeError:
        raise ConfigError("invalid JSON: not UTF-8 text", file=path) from None
    except OSError as exc:
        raise ConfigError(f"cannot read: {exc.strerror}", file=path) from None
    why = _metrics_problem(metrics)
    if why is not None:
        raise ConfigError(f"not a run's metrics: {why}", file=path)
    return metrics


def _metrics_problem(metrics: Any) -> str | None:
    if not isinstance(metrics, dict):
        return f"expected an object, got {type(metrics).__name__}"
    phases = metrics.get("phases", [])
    if not isinstance(phases, list):
        return "phases is not a list"
    for i, phase in enumerate(phases):
        if not isinstance(phase, dict):
            return f"phases[{i}] is not an object"
        if not _is_number(phase.get("start")):
            return f"phases[{i}].start is not a number"
        if not isinstance(phase.get("set", {}), dict):
            return f"phases[{i}].set is not an object"
    quality = metrics.get("quality")
    if quality is not None:
        if not isinstance(quality, dict) or not isinstance(quality.get("signal"), str):
            return "quality is not an object with a signal"
        for key in ("reference", "tolerance"):
            if not _is_number(quality.get(key)):
                return f"quality.{key} is not a number"
    return None


def _is_number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)
