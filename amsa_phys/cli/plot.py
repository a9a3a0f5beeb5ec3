"""Redraw a run's distance-vs-time plot from its trace.csv and metrics.json."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from ..errors import ConfigError
from ..plots.distance import plot_distance


def add_args(p: argparse.ArgumentParser) -> None:
    """Arguments of ``amsa-phys plot``."""
    p.add_argument("rundir", help="a run directory written by `amsa-phys run`")
    p.add_argument("-o", "--output", help="output PNG (default RUNDIR/distance.png)")


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
    plot_distance(rundir / "trace.csv", metrics, out)
    print(f"wrote {out}")
    return 0
