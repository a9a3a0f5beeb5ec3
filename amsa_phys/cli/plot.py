"""Redraw a run's distance-vs-time and trajectory plots from its trace.csv and metrics.json."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from ..errors import ConfigError
from ..runs.plotjob import draw_run_plots


def add_args(p: argparse.ArgumentParser) -> None:
    """Arguments of ``amsa-phys plot``."""
    p.add_argument("rundir", help="a run directory written by `amsa-phys run`")
    p.add_argument(
        "-o",
        "--output",
        help="distance plot PNG (default RUNDIR/distance.png; the trajectory plot "
        "goes next to it as <name>-trajectory.png, or RUNDIR/trajectory.png)",
    )


def run(args: argparse.Namespace) -> int:
    """Draw the plot."""
    rundir = Path(args.rundir)
    for name in ("trace.csv", "metrics.json"):
        if not (rundir / name).is_file():
            raise ConfigError(f"not a run directory: {name} is missing", file=rundir)
    try:
        metrics = json.loads((rundir / "metrics.json").read_text())
    except json.JSONDecodeError as exc:
        raise ConfigError(
            f"invalid JSON: {exc.msg}", file=rundir / "metrics.json", line=exc.lineno
        ) from None
    out = Path(args.output) if args.output else rundir / "distance.png"
    traj = out.with_name(out.stem + "-trajectory.png") if args.output else rundir / "trajectory.png"
    draw_run_plots(rundir / "trace.csv", metrics, out, traj)
    print(f"wrote {out} and {traj}")
    return 0
