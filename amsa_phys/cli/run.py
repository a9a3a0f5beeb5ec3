"""Run one scenario and write its run directory."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from ..engine import interrupt
from ..errors import ConfigError, one_line
from ..model.configure import with_ros2
from ..model.scenario import Scenario, load_scenario, traced_columns, without_adapt
from ..model.tracecols import LARGE_TRACE_BYTES, estimate_trace_bytes, size_text
from ..runs.expect import check_expectations
from ..runs.overrides import timeline_notes
from ..runs.plotjob import PlotJob
from ..runs.references import reference_notes
from ..runs.rundir import default_run_dir, run_dir_for
from ..runs.single import run_scenario
from ..runs.suite import input_files
from .options import (
    add_bag,
    add_no_adapt,
    add_output,
    add_ros2,
    add_scenario_overrides,
    add_trace_columns,
)
from .recording import add_recording, recording_options, recording_target, snapshot_options
from .report import print_summary

if TYPE_CHECKING:  # pygame is imported only by runs that draw, mcap only by --bag
    from ..bag import BagRecorder
    from ..view.video import RecordOptions, SnapshotOptions


def add_args(p: argparse.ArgumentParser) -> None:
    """Arguments of ``amsa-phys run``."""
    p.add_argument("scenario", help="scenario YAML file")
    p.add_argument(
        "--headless",
        action="store_true",
        help="no window: run as fast as possible (default: the interactive window)",
    )
    add_scenario_overrides(p)
    add_no_adapt(p)
    add_trace_columns(p)
    add_output(p)
    add_recording(p)
    add_bag(p)
    add_ros2(p)
    p.add_argument(
        "--no-plot", action="store_true", help="skip the plots (distance.png, trajectory.png)"
    )
    p.add_argument(
        "-q",
        "--quiet",
        action="store_true",
        help="no summary table (nor the lines under it, bag: or the ROS 2 waiting line); "
        "the expect verdicts, warnings and errors still print",
    )


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


def bag_apart(bag: Path, out: Path) -> None:
    """Refuse, before running, a ``--bag`` that is the run directory or holds it: the run
    would end, then fail writing the bag."""
    where = bag.resolve()
    run_dir = out.resolve()
    if where == run_dir or where in run_dir.parents:
        raise ConfigError("is the run directory (--out): name another file", key="--bag", file=bag)


def _run(
    args: argparse.Namespace,
    record: RecordOptions | None,
    snapshot: SnapshotOptions | None,
    plotter: PlotJob | None,
) -> int:
    if not args.headless:
        from ..view.window import open_display

        try:
            open_display(interactive=True)
        except RuntimeError as exc:
            raise ConfigError(f"{exc}; run with --headless", key="run") from None
    scenario = load_scenario(
        args.scenario,
        overrides=args.overrides,
        seed=args.seed,
        duration=args.duration,
        log_rate=args.log_rate,
        trace_columns=args.trace_columns,
    )
    if args.no_adapt:
        scenario = without_adapt(scenario)
    scenario = with_ros2(scenario, args.ros2, args.ros2_timeout)
    if scenario.ros2:  # before the run directory is made: one line if rclpy is missing
        from ..ros.ros2 import env, notice

        env.rclpy()
        if args.quiet:  # no "waiting up to 60 s for ROS 2 node ..." line either
            notice.quiet()
    for note in timeline_notes(scenario, args.overrides, "--set"):  # as the sweep warns
        print(one_line(f"warning: {note}"), file=sys.stderr)
    for note in reference_notes(scenario):
        print(one_line(f"warning: {note}"), file=sys.stderr)
    if snapshot is not None and snapshot.at is not None and snapshot.at > scenario.duration:
        raise ConfigError(
            f"{float(snapshot.at):g} s is after the run's end ({float(scenario.duration):g} s); "
            "leave it out for a snapshot of the last instant",
            key="--snapshot-at",
        )
    warn_if_trace_is_large(scenario)
    bag_path = (
        recording_target(args.bag, (".mcap",), "--bag", args.force)
        if args.bag is not None
        else None
    )
    out = Path(args.out) if args.out else default_run_dir(scenario.name)
    if bag_path is not None:
        bag_apart(bag_path, out)
    with run_dir_for(out, args.force, inputs=input_files(scenario)) as work:
        bag: BagRecorder | None = None
        if bag_path is not None:  # mcap and the message tables (~60 ms) only for --bag
            from ..bag import BagRecorder

            bag = BagRecorder(bag_path, scenario)
        try:
            with interrupt.sigterm_as_ctrl_c():
                outcome = run_scenario(
                    scenario,
                    work,
                    plot=not args.no_plot,
                    record=record,
                    snapshot=snapshot,
                    window=not args.headless,
                    plotter=plotter,
                    simulation=bag.simulation if bag is not None else None,
                    shown=out,
                )
        finally:
            written = bag.close() if bag is not None else None  # whatever ended the run
    if not args.quiet:
        print_summary(outcome.metrics, out, sys.stdout)
        if written is not None:
            print(f"bag: {written}")
    checks = check_expectations(scenario.expect, outcome.metrics, out / "trace.csv")
    # every verdict on stdout, in order (``run > log`` keeps them all, FAIL lines included);
    # the failure itself is said once on stderr and by the exit code
    for check in checks:
        print(one_line(f"expect {check.describe()}"))
    failed = [c.what for c in checks if not c.passed]
    if failed:
        sys.stdout.flush()  # the verdicts before the error line on a shared terminal
        print(
            one_line(
                f"error: {len(failed)} {'check' if len(failed) == 1 else 'checks'} of "
                f"{len(checks)} failed: {', '.join(failed)}"
            ),
            file=sys.stderr,
        )
    return 0 if not failed else 1


def warn_if_trace_is_large(scenario: Scenario) -> None:
    """One line on stderr before a run whose trace will pass ~1 GB (a wide, long run), with
    the two options that shrink it, so nobody finds a full disk an hour later."""
    columns = traced_columns(scenario)
    rate, duration = float(scenario.log_rate), float(scenario.duration)
    size = estimate_trace_bytes(len(columns), rate, duration)
    if size >= LARGE_TRACE_BYTES:
        print(
            one_line(
                f"amsa-phys: note: trace.csv will be {size_text(size)} "
                f"({len(columns):,} columns at {rate:g} Hz for {duration:g} s); "
                "--trace-columns or --log-rate make it smaller"
            ),
            file=sys.stderr,
        )
