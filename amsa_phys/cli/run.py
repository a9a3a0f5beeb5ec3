"""Run one scenario and write its run directory."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from ..engine import interrupt
from ..errors import ConfigError, one_line
from ..model.scenario import load_scenario
from ..runs.expect import check_expectations
from ..runs.plotjob import PlotJob
from ..runs.rundir import default_run_dir, prepare_run_dir
from ..runs.single import run_scenario
from ..runs.suite import input_files
from .options import add_output, add_scenario_overrides
from .recording import add_recording, recording_options, snapshot_options
from .report import print_summary

if TYPE_CHECKING:  # pygame is imported only by runs that draw
    from ..view.recorder import RecordOptions, SnapshotOptions


def add_args(p: argparse.ArgumentParser) -> None:
    """Arguments of ``amsa-phys run``."""
    p.add_argument("scenario", help="scenario YAML file")
    p.add_argument(
        "--headless",
        action="store_true",
        help="no window: run as fast as possible (default: the interactive window)",
    )
    add_scenario_overrides(p)
    add_output(p)
    add_recording(p)
    p.add_argument(
        "--no-plot", action="store_true", help="skip the plots (distance.png, trajectory.png)"
    )
    p.add_argument("-q", "--quiet", action="store_true", help="no summary table")


def run(args: argparse.Namespace) -> int:
    """Load, run, report."""
    record = recording_options(args)
    snapshot = snapshot_options(args)
    # a headless run's plots: a child imports matplotlib while we load and simulate
    plotter = PlotJob.start() if args.headless and not args.no_plot else None
    try:
        return _run(args, record, snapshot, plotter)
    finally:
        if plotter is not None:
            plotter.close()


def _run(
    args: argparse.Namespace,
    record: RecordOptions | None,
    snapshot: SnapshotOptions | None,
    plotter: PlotJob | None,
) -> int:
    if not args.headless:
        from ..view.window import open_display

        try:
            open_display()
        except RuntimeError as exc:
            raise ConfigError(f"{exc}; run with --headless", key="run") from None
    scenario = load_scenario(
        args.scenario,
        overrides=args.overrides,
        seed=args.seed,
        duration=args.duration,
        log_rate=args.log_rate,
    )
    out = Path(args.out) if args.out else default_run_dir(scenario.name)
    prepare_run_dir(out, args.force, inputs=input_files(scenario))
    with interrupt.sigterm_as_ctrl_c():
        outcome = run_scenario(
            scenario,
            out,
            plot=not args.no_plot,
            record=record,
            snapshot=snapshot,
            window=not args.headless,
            plotter=plotter,
        )
    if not args.quiet:
        print_summary(outcome.metrics, out, sys.stdout)
    checks = check_expectations(scenario.expect, outcome.metrics, out / "trace.csv")
    for check in checks:
        print(
            one_line(f"expect {check.describe()}"), file=sys.stdout if check.passed else sys.stderr
        )
    return 0 if all(c.passed for c in checks) else 1
