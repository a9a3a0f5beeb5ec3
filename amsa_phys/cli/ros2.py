"""``amsa-phys ros2 lockstep PKG --out RUNDIR``: an exported ROS 2 package in the loop;
``amsa-phys ros2 robot PKG``: its controller side and robot boundary on a robot."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from ..engine import interrupt
from ..errors import ConfigError, one_line
from ..model.wording import plural
from ..runs.expect import check_expectations
from ..runs.rundir import default_run_dir, prepare_run_dir
from ..runs.single import run_scenario
from .options import add_bag
from .recording import recording_target
from .report import print_summary
from .run import bag_apart


def add_args(p: argparse.ArgumentParser) -> None:
    """Arguments of ``amsa-phys ros2``."""
    sub = p.add_subparsers(dest="action", required=True, metavar="ACTION")
    lock = sub.add_parser(
        "lockstep",
        help="run an exported ROS 2 package's nodes against the simulator, in lockstep",
        description="Start every node of a package made by `amsa-phys export ros2` (no ros2 "
        "launch needed), run its scenario with those Leaves stepped by the nodes, and write "
        "the run directory: trace.csv byte for byte as `amsa-phys run` writes it.",
    )
    lock.add_argument("package", metavar="PKG", help="the package directory")
    lock.add_argument("--out", metavar="DIR", help="run directory (default runs/<scenario>-...)")
    lock.add_argument("--force", action="store_true", help="replace an existing --out")
    lock.add_argument(
        "--ros2-timeout",
        type=float,
        metavar="S",
        help="wall seconds a node may take to answer a step (default 10)",
    )
    lock.add_argument("--no-plot", action="store_true", help="skip the plots")
    add_bag(lock)
    lock.add_argument(
        "-q", "--quiet", action="store_true", help="no summary table, no start-up lines"
    )
    # refused with the way to do it: the package's length is set when it is exported
    lock.add_argument("--duration", metavar="S", help=argparse.SUPPRESS)
    robot = sub.add_parser(
        "robot",
        help="run an exported ROS 2 package's controller side on a robot (sim:=false)",
        description="Start the controller side of a package made by `amsa-phys export ros2` "
        "and its robot boundary, without the simulator (the launch file's sim:=false, no ros2 "
        "launch needed): the robot's drivers' standard messages in, the wheel commands out as "
        "sensor_msgs/JointState, /clock from the wall clock. Runs until Ctrl-C.",
    )
    robot.add_argument("package", metavar="PKG", help="the package directory")
    robot.add_argument(
        "--speed", type=float, default=1.0, metavar="X", help="/clock runs X times the wall clock"
    )
    robot.add_argument(
        "--no-frame-check",
        action="store_true",
        help="accept a driver's message whatever its header.frame_id",
    )


def run(args: argparse.Namespace) -> int:
    """The action's own function."""
    return _robot(args) if args.action == "robot" else _lockstep(args)


def _robot(args: argparse.Namespace) -> int:
    """Print what the boundary reads and writes, start the nodes, wait for Ctrl-C."""
    from ..ros.ros2 import env, robotrun
    from ..ros.ros2.robotplan import table

    the_plan = robotrun.plan(Path(args.package), args.speed, not args.no_frame_check)
    env.rclpy("ros2 robot")  # after the package: a wrong path is said first
    side = ", ".join(the_plan.robot.plan.controller)
    print(f"robot side: {side} and amsa_boundary; standard messages:")
    for line in table(the_plan.robot):
        print(line)
    sys.stdout.flush()
    try:
        with interrupt.sigterm_as_ctrl_c():
            robotrun.run(the_plan)
    except KeyboardInterrupt:
        print("stopped: every node ended")
    return 0


def _lockstep(args: argparse.Namespace) -> int:
    """Start the nodes, run, stop the nodes, report."""
    from ..ros.ros2 import env, notice
    from ..ros.ros2.lockstep import nodes_running, plan, simulation

    if args.duration is not None:
        raise ConfigError(
            "a package's duration is fixed when it is exported: amsa-phys export ros2 "
            f"SCENARIO --duration {args.duration} -o {args.package} --force",
            key="--duration",
        )
    if args.quiet:
        notice.quiet()
    the_plan = plan(Path(args.package), args.ros2_timeout)  # a bad path before a missing rclpy
    env.rclpy("ros2 lockstep")
    scenario = the_plan.scenario
    out = Path(args.out) if args.out else default_run_dir(scenario.name)
    bag_path = (
        recording_target(args.bag, (".mcap",), "--bag", args.force)
        if args.bag is not None
        else None
    )
    if bag_path is not None:
        bag_apart(bag_path, out)
    prepare_run_dir(out, args.force)
    leaves = list(the_plan.commands)
    notice.say(
        f"starting {plural(len(leaves), 'node')} of {args.package} "
        f"({', '.join(leaves) or 'none'}; ROS_DOMAIN_ID={notice.domain()}), then "
        f"{float(scenario.duration):g} simulated s in lockstep"
    )
    bag = None
    if bag_path is not None:  # the bag a `run --bag` writes, byte for byte
        from ..bag import BagRecorder

        bag = BagRecorder(bag_path, scenario)
    try:
        with interrupt.sigterm_as_ctrl_c(), nodes_running(the_plan.commands) as procs:
            make = simulation(the_plan, procs)

            def recorded(sc: Any, trace: Any) -> Any:
                sim = make(sc, trace)
                if bag is not None:
                    bag.attach(sim)
                return sim

            outcome = run_scenario(scenario, out, plot=not args.no_plot, simulation=recorded)
    finally:
        written = bag.close() if bag is not None else None  # whatever ended the run
    if not args.quiet:
        print_summary(outcome.metrics, out, sys.stdout)
        if written is not None:
            print(f"bag: {written}")
    checks = check_expectations(scenario.expect, outcome.metrics, out / "trace.csv")
    for check in checks:
        print(one_line(f"expect {check.describe()}"))
    failed = [c.what for c in checks if not c.passed]
    if failed:
        sys.stdout.flush()
        print(one_line(f"error: {len(failed)} of {len(checks)} checks failed"), file=sys.stderr)
    return 1 if failed else 0
