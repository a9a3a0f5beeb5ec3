"""The robot boundary of an exported ROS 2 package, as a plan: no rclpy, so the starter, the
docs' table and the tests read it.

Which sensor streams the drivers publish and which nodes form the controller side come from
``ros/boundary.py``'s plan (the same for ROS 1's ``sim:=false``); this adds the ROS 2 side:
the message types' ROS 2 names, the QoS of each direction, the wheel-command streams whose
powers the controller side produces, and the table of topics ``ros2 robot`` prints and the
docs hold.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

from ...model.scenario import Scenario
from ...model.world import WorldSpec
from ...stdmsgs import Source
from .. import external, names
from ..boundary import Plan, buffers_of, plan
from ..graph import RosGraph

#: QoS of the topics the boundary node reads from a robot's drivers, and of what it publishes
SENSOR_QOS = "BEST_EFFORT, VOLATILE, KEEP_LAST(10)"
COMMAND_QOS = external.DATA_QOS
#: A ROS 2 message type by its ROS 1 / bag name (``stdmsgs``'s ``pkg/Type``)
ROS2_TYPE = {
    "sensor_msgs/NavSatFix": "sensor_msgs/msg/NavSatFix",
    "sensor_msgs/Imu": "sensor_msgs/msg/Imu",
    "nav_msgs/Odometry": "nav_msgs/msg/Odometry",
    "sensor_msgs/LaserScan": "sensor_msgs/msg/LaserScan",
    "sensor_msgs/JointState": "sensor_msgs/msg/JointState",
}


@dataclass(frozen=True)
class Robot:
    """What the boundary of one package does on a robot: streams in, commands out."""

    plan: Plan
    world: WorldSpec
    #: sensor streams read from the drivers
    inbound: list[Source]
    #: wheel commands written for the motors (their powers come from the controller side)
    outbound: list[Source]


def robot_of(scenario: Scenario, local: Iterable[str]) -> Robot:
    """The boundary of ``scenario``'s world with ``local`` Leaves in the simulator."""
    graph = RosGraph.of(scenario.world, local)
    the_plan = plan(graph)
    readers = {s.leaf for s in the_plan.inbound}
    produced = {b for p in the_plan.controller for b in graph.outputs(p)}
    out = [
        s
        for s in the_plan.sources
        if s.role.name == "WheelCommand"
        and s.leaf not in readers
        and all(b in produced for b in buffers_of(s))
    ]
    return Robot(the_plan, scenario.world, the_plan.inbound, out)


def table(robot: Robot) -> list[str]:
    """Every topic of the boundary with its type, direction and QoS (the start's report and
    the docs' table)."""
    lines = [f"  /clock  {external.CLOCK_TYPE}  published  {COMMAND_QOS}"]
    for s in robot.inbound:
        lines.append(
            f"  in   {s.topic}  {ROS2_TYPE[s.role.msg]}  frame {s.frame_id}  {SENSOR_QOS}"
            f"  -> {', '.join(names.topic(d) for d in _data(robot.world, s))}"
        )
    for s in robot.outbound:
        lines.append(
            f"  out  {s.topic}  {ROS2_TYPE[s.role.msg]}  <- "
            f"{', '.join(names.topic(b) for b in buffers_of(s))}  {COMMAND_QOS}"
        )
    return lines


def markdown(robot: Robot) -> list[str]:
    """:func:`table` as the docs' Markdown table (a test compares the docs with it)."""
    rows = [
        "| topic | type | direction | frame_id | QoS | data topics |",
        "|---|---|---|---|---|---|",
        f"| `/clock` | `{external.CLOCK_TYPE}` | boundary → nodes, drivers | | {COMMAND_QOS} | |",
    ]
    for s in robot.inbound:
        data = ", ".join(f"`{names.topic(d)}`" for d in _data(robot.world, s))
        rows.append(
            f"| `{s.topic}` | `{ROS2_TYPE[s.role.msg]}` | driver → boundary | `{s.frame_id}` "
            f"| {SENSOR_QOS} | {data} |"
        )
    for s in robot.outbound:
        data = ", ".join(f"`{names.topic(b)}`" for b in buffers_of(s))
        rows.append(
            f"| `{s.topic}` | `{ROS2_TYPE[s.role.msg]}` | boundary → motors | `{s.frame_id}` "
            f"| {COMMAND_QOS} | {data} |"
        )
    return rows


def _data(world: WorldSpec, src: Source) -> list[str]:
    """The Data a stream's fields go to: scalars, and an array field's port (once)."""
    element = {e: a for a, elements in world.arrays.items() for e in elements}
    out: list[str] = []
    for buf in src.buffers.values():
        d = element[buf[0]] if isinstance(buf, tuple) else buf
        if d not in out:
            out.append(d)
    return out
