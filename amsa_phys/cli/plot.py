"""Redraw a run's plots from its trace and metrics, or a sweep's summary from results.csv."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from ..errors import AmsaError, ConfigError, one_line
from ..requirements.objective import requirement_of
from ..runs.outfile import check_output_file, drawn_by_us
from ..runs.plotjob import draw_run_plots, plot_context
from ..runs.rundata import read_world
from ..runs.rundir import check_output
from ..runs.runfiles import read_metrics, trace_header
from ..runs.sweep import read_results, unknown_sweep_metric
from .paperplots import plot_losses, plot_starts
from .paperruns import paper_run, paper_scenarios


def add_args(p: argparse.ArgumentParser) -> None:
    """Arguments of ``amsa-phys plot``."""
    p.add_argument(
        "rundir",
        nargs="*",
        help="a run directory (`amsa-phys run`), a sweep directory (`amsa-phys sweep`) or "
        "a falsification's (`amsa-phys falsify`: its runs as samples.png); "
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
        "for a sweep: the summary PNG (default DIR/summary.png); an existing file is "
        "replaced only if amsa-phys drew it",
    )
    p.add_argument(
        "--force",
        action="store_true",
        help="replace an existing -o file that amsa-phys did not draw (a link: the link)",
    )
    p.add_argument(
        "--metric",
        help="sweep or falsification only: the metric to plot, overall or "
        "phase<i>.<metric> (default rms_error; a falsification: what it searched on)",
    )


#: The files of a run, sweep or falsify directory that ``plot`` reads: never an -o
INPUTS = ("results.csv", "scenario.yaml", "trace.csv", "metrics.json", "falsify.json")


def run(args: argparse.Namespace) -> int:
    """Draw the plot."""
    if args.output is not None:  # every kind of plot: the rule for a file given with -o
        check_output_file(
            Path(args.output), "--output", args.force, _inputs(args), ours=drawn_by_us
        )
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
        from .plot_falsify import plot_falsify, record_of

        if record_of(rundir) is not None:
            return plot_falsify(rundir, args)
        return _plot_sweep(rundir, args)
    trials = sorted(rundir.glob("trial-[0-9][0-9][0-9]"))
    if trials and not (rundir / "trace.csv").exists():
        raise ConfigError(
            f"a falsification's {len(trials)} trials (their summary is trials.png): plot one "
            f"of them, e.g. amsa-phys plot {trials[0]}",
            file=rundir,
        )
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
    if args.output:  # the trajectory beside -o: the same rule
        check_output_file(traj, "--output", args.force, _inputs(args), ours=drawn_by_us)
    written = draw_run_plots(rundir / "trace.csv", metrics, out, traj, _world_of(rundir))
    print(one_line("wrote " + " and ".join(str(p) for p in written)))
    if out not in written:
        print(f"no {out.name}: the scenario has no quality: section (no signal to plot)")
    return 0


def _inputs(args: argparse.Namespace) -> list[Path]:
    """The files this plot reads (a directory's files by name, a scenario file itself)."""
    found: list[Path] = []
    for given in map(Path, args.rundir):
        found += [given / name for name in INPUTS] if given.is_dir() else [given]
    return found


def _world_of(rundir: Path) -> dict[str, Any] | None:
    """The arena and GPS links from the run's resolved scenario.yaml, read as data (a
    module it names is not imported: :mod:`amsa_phys.runs.rundata`); None if it is absent
    or unreadable: the paths are then drawn without the static world."""
    path = rundir / "scenario.yaml"
    if not path.is_file():
        return None
    try:
        world = read_world(path, trace_header(rundir / "trace.csv"))
        return plot_context(world, world.resolved)  # type: ignore[arg-type]
    except (AmsaError, OSError) as exc:
        print(one_line(f"warning: {exc}; the paths are drawn without the world"), file=sys.stderr)
        return None


def _plot_sweep(sweepdir: Path, args: argparse.Namespace) -> int:
    """summary.png again, for any metric column: no need to rerun the sweep to see another."""
    from ..plots.summary import cut_of, nevers, plot_summary  # matplotlib: once rows are read

    rows, axes = read_results(sweepdir / "results.csv")
    metric = args.metric or "rms_error"
    phases = sum(1 for key in rows[0] if key.endswith(".rms_error")) if rows else 0
    requirements = [k for k in (requirement_of(c) for c in (rows[0] if rows else ())) if k]
    why = unknown_sweep_metric(metric, phases, requirements)
    if why is not None:
        raise ConfigError(why, key="--metric")
    seeds = len({r["seed_index"] for r in rows})
    out = Path(args.output) if args.output else sweepdir / "summary.png"
    check_output(out, "--output")
    name = _sweep_scenario(sweepdir)
    cut = cut_of(sweepdir / "summary.png")  # what the sweep's own title said of its runs
    title = one_line(
        f"{name}: {metric} ({seeds} seed{'s' if seeds != 1 else ''})" + (f"; {cut}" if cut else "")
    )
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
        return plot_losses(args) if args.paper == "fig6-sensed" else plot_starts(args)
    sources = [Path(s) for s in args.rundir] or paper_scenarios(args.paper)
    out = Path(args.output) if args.output else Path(f"paper_{args.paper}.png")
    check_output(out, "--output")
    runs = [paper_run(src) for src in sources]
    if args.paper == "fig5":
        runs.sort(key=lambda r: -(r.kv if r.kv is not None else -1.0))
        paper.fig5(runs, out)
    else:
        if len(runs) != 1:
            raise ConfigError("Fig. 6 is one run (Kv 0.35, then 0.05)", key="--paper fig6")
        paper.fig6(runs[0], out)
    print(one_line(f"wrote {out} ({len(runs)} run{'s' if len(runs) != 1 else ''})"))
    return 0
