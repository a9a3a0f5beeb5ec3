"""Options shared by several subcommands, defined once."""

from __future__ import annotations

import argparse
import os


def add_scenario_overrides(p: argparse.ArgumentParser) -> None:
    """--seed, --duration, --set, --log-rate."""
    p.add_argument("--seed", type=int, help="override the scenario's seed")
    p.add_argument(
        "--duration",
        type=float,
        metavar="S",
        help="override the duration (seconds of simulated time)",
    )
    p.add_argument(
        "--set",
        dest="overrides",
        action="append",
        default=[],
        metavar="Comp.param=V",
        help="set a parameter at t = 0 (repeatable); V is read as YAML",
    )
    p.add_argument(
        "--log-rate",
        type=float,
        metavar="HZ",
        help="trace rate (default 20 Hz, never below the fastest sensor)",
    )


def add_trace_columns(p: argparse.ArgumentParser) -> None:
    """--trace-columns: which Data buffers trace.csv keeps."""
    p.add_argument(
        "--trace-columns",
        metavar="GLOB,...",
        help="trace only the Data buffers matching these patterns, e.g. 'Car*.Gap.*,Leader.*' "
        "(the quality signal and expect: trace columns are always kept; default: all)",
    )


def add_output(p: argparse.ArgumentParser) -> None:
    """--out and --force."""
    p.add_argument(
        "--out", metavar="DIR", help="run directory (default runs/<scenario>-<YYYYmmdd-HHMMSS>)"
    )
    p.add_argument(
        "--force",
        action="store_true",
        help="replace an existing --out directory (and --record, --snapshot files)",
    )


def add_jobs(p: argparse.ArgumentParser) -> None:
    """-j/--jobs: worker processes, all cores by default."""
    p.add_argument(
        "-j",
        "--jobs",
        type=int,
        default=os.cpu_count() or 1,
        help="parallel worker processes (default: all cores)",
    )


def add_bag(p: argparse.ArgumentParser) -> None:
    """--bag: the run also as a ROS 2 MCAP bag."""
    p.add_argument(
        "--bag",
        metavar="FILE.mcap",
        help="also write the run as an MCAP bag with ROS 2 encodings: standard messages "
        "(NavSatFix, Imu, Odometry, LaserScan, tf), every traced buffer, the events",
    )


def add_no_adapt(p: argparse.ArgumentParser) -> None:
    """--no-adapt: the scenario with its ``adapt:`` rules off."""
    p.add_argument(
        "--no-adapt",
        action="store_true",
        help="turn the scenario's adapt: rules off (compare with fixed parameters)",
    )


def add_ros2(p: argparse.ArgumentParser) -> None:
    """--ros2 and --ros2-timeout: Leaves stepped by a user's ROS 2 nodes."""
    p.add_argument(
        "--ros2",
        metavar="COMP[,COMP]",
        help="these Leaves are your ROS 2 nodes: their inputs are published, their outputs "
        "awaited, in lockstep on /clock (replaces the scenario's ros2:; needs rclpy, "
        "docs/ros2.md; describe --ros2 lists the topics)",
    )
    p.add_argument(
        "--ros2-timeout",
        type=float,
        metavar="S",
        help="wall seconds a ROS 2 node may take to answer a step (default 10)",
    )
