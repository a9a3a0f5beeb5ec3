"""Export a scenario as a ROS package, or a world as the original AMSA files."""

from __future__ import annotations

import argparse
import dataclasses
import errno
import os
import sys
from fractions import Fraction
from pathlib import Path

from ..errors import ConfigError, one_line
from ..interop.exporter import export_world
from ..model.configure import duration_option, with_overrides
from ..model.scenario import (
    DEFAULT_LOG_RATE_HZ,
    Scenario,
    Timeline,
    load_scenario,
)
from ..model.template import Kind
from ..model.world import load_world
from ..model.yamlio import load_yaml
from ..runs.overrides import timeline_notes
from ..runs.rundir import commit_staged, discard_staged, staged_dir
from ..runs.suite import input_files
from .options import add_scenario_overrides

#: Simulated seconds a package exported from a bare world runs for.
WORLD_DURATION = 3600


def add_args(p: argparse.ArgumentParser) -> None:
    """Arguments of ``amsa-phys export ros|amsa``."""
    sub = p.add_subparsers(dest="target", required=True, metavar="TARGET")
    ros = sub.add_parser(
        "ros",
        help="a catkin package: a node per Leaf, a topic per Data, a parameter per Parameter",
        description="A ROS 1 catkin package named after the root component: a node per Leaf, "
        "a std_msgs/Float64 topic per Data, a parameter per Parameter, a scenario node, a "
        "simulator node publishing /clock, a launch file per scenario.",
    )
    ros.add_argument(
        "files", nargs="+", metavar="SCENARIO|WORLD", help="scenarios of one world, or a world"
    )
    ros.add_argument("-o", "--out", required=True, metavar="DIR", help="the package directory")
    ros.add_argument(
        "--mode",
        choices=("lockstep", "free"),
        default="lockstep",
        help="the launch files' default: lockstep reproduces amsa-phys run byte for byte; "
        "free runs every node on its own timer (default lockstep)",
    )
    ros.add_argument("--force", action="store_true", help="replace a DIR amsa-phys made")
    add_scenario_overrides(ros)
    ros2 = sub.add_parser(
        "ros2",
        help="a ROS 2 package (ament_python): an rclpy node per Leaf, parameters, launch.py",
        description="A ROS 2 package (package.xml format 3, ament_python): an rclpy node per "
        "Leaf outside the physics, a std_msgs/msg/Float64 topic per Data, a ROS 2 parameter "
        "per Parameter (range-checked), ros__parameters YAML, launch/NAME.launch.py; "
        "amsa-phys ros2 lockstep runs it against the simulator.",
    )
    ros2.add_argument("scenario", metavar="SCENARIO", help="the scenario")
    ros2.add_argument("-o", "--out", required=True, metavar="DIR", help="the package directory")
    ros2.add_argument("--force", action="store_true", help="replace a DIR amsa-phys made")
    ros2.add_argument(
        "--name",
        metavar="PKG",
        help="the package's name (default: the root component's in snake case, "
        "mdeChallenge -> mde_challenge; give each scenario of one world its own to build "
        "them in one workspace)",
    )
    ros2.add_argument("-q", "--quiet", action="store_true", help="print nothing on success")
    add_scenario_overrides(ros2)
    amsa = sub.add_parser(
        "amsa",
        help="the original AMSA files (.amsacore XMI, .amsatemplate)",
        description="The original AMSA tool's files: NAME.amsacore (XMI) and "
        "NAME.amsatemplate; amsa-phys import reads them back to the same world.",
    )
    amsa.add_argument("world", metavar="WORLD", help="a world (or a scenario: its world)")
    amsa.add_argument("-o", "--out", required=True, metavar="DIR", help="where to write")
    amsa.add_argument("--force", action="store_true", help="replace a DIR amsa-phys made")


def run(args: argparse.Namespace) -> int:
    """Generate into a staged directory, then rename it into place."""
    out = Path(args.out)
    if args.target == "amsa":
        return _amsa(args, out)
    if args.target == "ros2":
        return _ros2(args, out)
    return _ros(args, out)


def _load(path: str, args: argparse.Namespace) -> Scenario:
    """A scenario file, or a bare world as a scenario with no timeline.

    A scenario stays whole under ``--duration``: the package keeps the cut apart and its run
    applies it as ``run --duration`` does (``ros/exported.py``); it is judged and warned about
    here as that run would be."""
    doc = load_yaml(path)
    if isinstance(doc.data, dict) and "world" in doc.data:
        options = {"overrides": args.overrides, "seed": args.seed, "log_rate": args.log_rate}
        scenario = load_scenario(path, duration=args.duration, **options)
        for note in timeline_notes(scenario, args.overrides, "--set"):  # as `run` warns
            print(one_line(f"warning: {note}"), file=sys.stderr)
        return scenario if args.duration is None else load_scenario(path, **options)
    world = load_world(path)
    rate = Fraction(str(args.log_rate)) if args.log_rate else Fraction(DEFAULT_LOG_RATE_HZ)
    bare = Scenario(
        path=Path(path),
        name=world.name,
        world=world,
        timeline=Timeline.of([], Fraction(str(args.duration or WORLD_DURATION))),
        seed=args.seed or 0,
        log_rate=rate,
        quality=None,
    )
    # the scenario's own path for --set: physics settings, frequencies, and a key set twice
    # refused in one line (as `run` and a scenario file do)
    scenario = with_overrides(bare, list(args.overrides), None)
    world = scenario.world  # a frequency set by --set counts for the log rate
    sensors = [leaf.freq for leaf in world.leaves.values() if leaf.kind is Kind.SENSOR]
    return dataclasses.replace(scenario, log_rate=max([rate, *sensors]))


def _cut(args: argparse.Namespace) -> Fraction | None:
    """``--duration`` of a scenario's package, kept apart from its whole scenario (a bare
    world's timeline already has that length)."""
    if args.duration is None:
        return None
    return duration_option(args.duration)


def _cut_line(scenario: Scenario, cut: Fraction, where: str) -> str:
    """What ``--duration`` made of the package: the run's length, kept apart."""
    return (
        f"it runs {float(cut):g} s ({where}; the scenario file keeps its "
        f"{float(scenario.duration):g} s): as run --duration, the checks it cannot judge are "
        "reported skipped"
    )


def _ros(args: argparse.Namespace, out: Path) -> int:
    from ..ros.generate import check_names, generate

    scenarios = [_load(f, args) for f in args.files]
    check_names(scenarios, list(args.files))  # before anything is written
    inputs = [p for s in scenarios for p in input_files(s)]
    staged = staged_dir(out, args.force, inputs)
    try:
        package = generate(scenarios, list(args.files), args.mode, staged, _cut(args))
        _commit(staged, out, args.force)
    except BaseException:
        discard_staged(staged)
        raise
    nodes = len(package.nodes)
    cpp = f"; C++ nodes: {', '.join(package.cpp)}" if package.cpp else ""
    print(
        f"wrote ROS package {package.name} in {out}: {nodes} nodes (physics in amsa_simulator: "
        f"{', '.join(package.local) or 'none'}{cpp}); launch files: {', '.join(package.launch)}"
    )
    print(f"build it in a catkin workspace (WS/src/{package.name}): see {out / 'README.md'}")
    cut = _cut(args)
    if cut is not None:
        print(_cut_line(scenarios[0], cut, "the launch files' duration:= default"))
    return 0


def _ros2(args: argparse.Namespace, out: Path) -> int:
    from ..ros.ros2.export import generate as generate2

    scenario = _load(args.scenario, args)
    if "world" not in (scenario.data or {}):
        raise ConfigError(
            "expected a scenario (a world has no timeline to run)", file=args.scenario
        )
    staged = staged_dir(out, args.force, input_files(scenario))
    try:
        package = generate2(scenario, args.scenario, staged, _cut(args), args.name)
        _commit(staged, out, args.force)
    except BaseException:
        discard_staged(staged)
        raise
    if args.quiet:
        return 0
    print(
        f"wrote ROS 2 package {package.name} in {out}: {len(package.nodes)} rclpy nodes "
        f"({', '.join(package.nodes) or 'none'}; physics in amsa-phys: "
        f"{', '.join(package.local) or 'none'})"
    )
    print(f"run it against the simulator: amsa-phys ros2 lockstep {out} --out RUNDIR")
    cut = _cut(args)
    if cut is not None:
        print(_cut_line(scenario, cut, "config/amsa.yaml"))
    if package.robot:
        print(f"on a robot ({', '.join(package.robot)}): amsa-phys ros2 robot {out}")
    return 0


def _amsa(args: argparse.Namespace, out: Path) -> int:
    doc = load_yaml(args.world)
    if isinstance(doc.data, dict) and "world" in doc.data:
        world = load_scenario(args.world).world
    else:
        world = load_world(args.world)
    try:
        exported = export_world(world)
    except ValueError as exc:
        raise ConfigError(str(exc), file=args.world) from None
    staged = staged_dir(out, args.force, [Path(args.world)])
    try:
        (staged / exported.core_name).write_text(exported.core_text)
        (staged / exported.template_name).write_text(exported.template_text)
        _commit(staged, out, args.force)
    except BaseException:
        discard_staged(staged)
        raise
    print(f"wrote {out / exported.core_name} and {out / exported.template_name}")
    return 0


def _commit(staged: Path, out: Path, force: bool) -> None:
    """Put the staged tree in place; without ``--force`` never replace what appeared meanwhile.

    The output was checked (absent or empty) before generating, but another export may have
    created it since. Without ``--force`` one ``rename`` does it: the kernel renames a
    directory only onto nothing or an empty directory, so of concurrent exports exactly one
    wins and the others fail here (exit 2) instead of silently replacing it.
    """
    if force:
        commit_staged(staged, out, flag="-o")
        return
    try:
        os.rename(staged, out)
    except OSError as exc:
        if exc.errno in (errno.EEXIST, errno.ENOTEMPTY, errno.ENOTDIR, errno.EISDIR):
            raise ConfigError(
                "was created by someone else while exporting (use --force to replace it)",
                key="-o",
                file=out,
            ) from None
        raise ConfigError(f"cannot write: {exc.strerror}", key="-o", file=out) from None
