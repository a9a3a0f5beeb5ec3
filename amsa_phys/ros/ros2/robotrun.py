"""``amsa-phys ros2 robot PKG``: an exported package's controller side on a robot, no launch.

What the launch file's ``sim:=false`` starts, without ``ros2 launch`` (the wheels this is
tested with have none): the controller side's nodes (``ros/boundary.py``'s plan), each a
process of this Python with the package's ``ros__parameters`` file and its inputs on the
data topics themselves (no lockstep remapping, no step trigger: a node steps on each full
set of inputs at the latest ``/clock``), and the boundary node ``amsa_boundary``
(``robot.py``). They run until Ctrl-C or SIGTERM; a node that exits is a fault naming it.
"""

from __future__ import annotations

import dataclasses
import sys
import time
from pathlib import Path

from ...errors import AmsaError, ConfigError
from .lockstep import nodes_running, read_package
from .robotplan import Robot, robot_of

#: How often the starter looks whether a node exited (a poll of the processes, wall s)
LOOK_S = 0.2


class NodeExited(AmsaError):
    """A node of the robot's side exited while the robot ran (exit 2, as a node's fault)."""

    exit_code = 2


@dataclasses.dataclass
class RobotPlan:
    """The boundary, and each node's command (the boundary's under ``amsa_boundary``)."""

    robot: Robot
    commands: dict[str, list[str]]


def plan(pkg: Path, speed: float = 1.0, check_frames: bool = True) -> RobotPlan:
    """Read the package; the controller side's commands and the boundary's."""
    if not speed > 0 or speed == float("inf"):
        raise ConfigError(f"expected a positive number, got {speed!r}", key="--speed")
    package = read_package(pkg)
    if package.boundary is None:
        raise ConfigError(
            "this package has no robot boundary (export it again with this amsa-phys)",
            file=pkg / "config" / "amsa.yaml",
        )
    robot = robot_of(package.scenario, package.local)
    if not robot.plan.controller:
        raise ConfigError(
            "no node of this package can run on a robot: every controller reads a value no "
            "robot measures (a monitor of the true state); see the ROS 2 docs, On a robot",
            file=pkg / "config" / "amsa.yaml",
        )
    commands: dict[str, list[str]] = {}
    params = ["--ros-args", "--params-file", str(package.params)]
    for path in robot.plan.controller:
        commands[path] = [sys.executable, str(package.scripts[path]), *params]
    commands["amsa_boundary"] = [
        sys.executable,
        str(package.boundary),
        "--ros-args",
        "-p",
        f"speed:={float(speed)!r}",
        "-p",
        f"check_frames:={'true' if check_frames else 'false'}",
    ]
    return RobotPlan(robot, commands)


def run(the_plan: RobotPlan) -> None:
    """Start every node, wait until interrupted (KeyboardInterrupt) or a node exits
    (:class:`NodeExited`); every node is stopped either way."""
    with nodes_running(the_plan.commands) as procs:
        while True:
            for name, proc in procs.items():
                if proc.poll() is not None:
                    raise NodeExited(f"ROS 2 node {name} exited with status {proc.returncode}")
            time.sleep(LOOK_S)  # a poll of the node processes, not a pacing of anything


__all__ = ["NodeExited", "RobotPlan", "plan", "run"]
