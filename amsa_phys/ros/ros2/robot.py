"""The ROS 2 package's robot boundary node: a robot's drivers in, the wheel commands out.

With ``sim:=false`` (``launch/NAME.launch.py``) or ``amsa-phys ros2 robot PKG`` no simulator,
scenario or sensor model runs: only the controller side (``ros/boundary.py``'s plan, the same
for ROS 1's ``sim:=false``) and this node, ``amsa_boundary``. It

* reads each sensor stream a robot's drivers publish (``sensor_msgs/msg/NavSatFix``, ``Imu``,
  ``nav_msgs/msg/Odometry``, ``LaserScan``, as the world's sensors need) on the topic the
  stream has in the MCAP bag and the ROS 1 export, judges it (``ros/boundary.py``'s
  :func:`~amsa_phys.ros.boundary.judge`, the one mapping both targets use) and publishes
  its fields on the data topics the controller side reads (``std_msgs/msg/Float64``, an array
  port's ``Float64MultiArray``); a message refused is dropped with one warning line naming
  the topic and why;
* turns the controller side's wheel powers into ``sensor_msgs/msg/JointState`` on
  ``/ROBOT/wheel_cmd`` (``stdmsgs``'s builder: joints ``left_wheel_joint``,
  ``right_wheel_joint``, ``effort`` the power in %), the ROS 1 export's command message;
* publishes ``/clock`` from the wall clock (times ``speed``), as ROS 1's does: every node of
  the package steps on ``/clock`` (``use_sim_time``).

Sensor streams are read BEST_EFFORT (a driver publishing with the sensor-data QoS, best
effort, matches only a best-effort reader; a reliable driver matches too); what this node
publishes is RELIABLE, as the package's data topics are.
"""

from __future__ import annotations

import math
import sys
import threading
import time
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from ...errors import AmsaError, ConfigError
from ...model.scenario import Scenario, load_scenario
from ...model.yamlio import load_yaml
from ...stdmsgs import DEFAULT_ORIGIN, Context, Source, build
from .. import external, names
from ..boundary import NODE, Refused, buffers_of, judge
from ..runtime.arrays import ScanShape
from . import env
from .robotplan import COMMAND_QOS, ROS2_TYPE, SENSOR_QOS, Robot, robot_of
from .spin import spin_until_shutdown

#: ``/clock`` period (wall seconds): finer than any Leaf's period, as ROS 1's boundary
CLOCK_PERIOD = 0.005
#: How often the node looks for a driver publishing another type on a sensor topic (wall s)
GRAPH_LOOK_S = 1.0
#: the node name the graph gives a publisher whose node it has not discovered yet
UNKNOWN_NODE = "_NODE_NAME_UNKNOWN_"
#: graph looks a wrong-typed publisher may stay unnamed before it is said without its name
UNNAMED_LOOKS = 10


def qos(text: str) -> Any:
    """The rclpy profile a QoS line of the docs' table states (``RELIABLE, VOLATILE,
    KEEP_LAST(10)``): the table and the node cannot disagree."""
    from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

    reliability, durability, history = (part.strip() for part in text.split(","))
    depth = int(history.removeprefix("KEEP_LAST(").removesuffix(")"))
    return QoSProfile(
        depth=depth,
        reliability=ReliabilityPolicy[reliability],
        durability=DurabilityPolicy[durability],
        history=HistoryPolicy.KEEP_LAST,
    )


def fill(msg: Any, fields: Mapping[str, Any]) -> Any:
    """A ROS 2 message from ``stdmsgs``'s dict of its fields (nested dicts: sub-messages)."""
    for key, value in fields.items():
        if isinstance(value, Mapping):
            fill(getattr(msg, key), value)
        else:
            setattr(msg, key, value)
    return msg


def _classes() -> dict[str, Any]:
    from nav_msgs.msg import Odometry
    from sensor_msgs.msg import Imu, JointState, LaserScan, NavSatFix

    return {
        "sensor_msgs/NavSatFix": NavSatFix,
        "sensor_msgs/Imu": Imu,
        "nav_msgs/Odometry": Odometry,
        "sensor_msgs/LaserScan": LaserScan,
        "sensor_msgs/JointState": JointState,
    }


class Boundary:
    """The node's subscriptions and publishers (``node``: an rclpy node of name ``NODE``)."""

    def __init__(self, node: Any, scenario: Scenario, robot: Robot, check_frames: bool) -> None:
        from std_msgs.msg import Float64, Float64MultiArray

        self.node = node
        self.robot = robot
        self.check_frames = check_frames
        self.world = scenario.world
        self.params = external.start_values(scenario)
        self.classes = _classes()
        self.Float64, self.Array = Float64, Float64MultiArray
        reliable, best_effort = qos(COMMAND_QOS), qos(SENSOR_QOS)  # as the docs' table says
        self.lock = threading.Lock()
        self.stamp = (0, 0)  # the last /clock published
        #: per sensor topic: the reasons said since its last good message (one line each)
        self.refusing: dict[str, set[str]] = {}
        self.refused: dict[str, int] = {}
        self.wrong_types: set[tuple[str, str]] = set()
        #: graph looks so far at which a wrong-typed publisher's node had no name yet
        self.unnamed: dict[tuple[str, str], int] = {}
        element = {e: a for a, elements in self.world.arrays.items() for e in elements}
        self.element = element
        self.data_pubs: dict[str, Any] = {}
        self.scans: dict[str, ScanShape] = {}
        for src in robot.inbound:
            if src.role.name == "LaserScan":
                self.scans[src.leaf] = ScanShape.of(self.params[src.leaf])
            for b in buffers_of(src):
                d = element.get(b, b)
                if d not in self.data_pubs:
                    cls = Float64MultiArray if d in self.world.arrays else Float64
                    self.data_pubs[d] = node.create_publisher(cls, names.topic(d), reliable)
            self.refusing[src.topic] = set()
            self.refused[src.topic] = 0
            node.create_subscription(
                self.classes[src.role.msg],
                src.topic,
                lambda msg, src=src: self._on_driver(src, msg),
                best_effort,
            )
        self.values: dict[str, float] = {b: float(s.initial) for b, s in self.world.buffers.items()}
        self.fresh: dict[str, set[str]] = {}
        self.cmd_pubs: dict[str, Any] = {}
        for src in robot.outbound:
            self.fresh[src.topic] = set()
            self.cmd_pubs[src.topic] = node.create_publisher(
                self.classes[src.role.msg], src.topic, reliable
            )
            for b in buffers_of(src):
                node.create_subscription(
                    Float64,
                    names.topic(b),
                    lambda msg, src=src, b=b: self._on_power(src, b, msg),
                    reliable,
                )
        from rosgraph_msgs.msg import Clock

        self.Clock = Clock
        self.clock_pub = node.create_publisher(Clock, names.CLOCK, reliable)
        node.create_timer(GRAPH_LOOK_S, self._look_at_graph)

    # -- in ---------------------------------------------------------------------------------
    def _on_driver(self, src: Source, msg: Any) -> None:
        """A driver's message: its fields on their data topics, or one line saying why not."""
        frame = src.frame_id if self.check_frames else None
        try:
            fields = judge(src, msg, DEFAULT_ORIGIN, self.scans.get(src.leaf), frame)
        except Refused as exc:
            self.refused[src.topic] += 1
            why = str(exc)
            if why not in self.refusing[src.topic]:  # one line per reason, not per message
                self.refusing[src.topic].add(why)
                self.node.get_logger().warning(
                    f"dropped {ROS2_TYPE[src.role.msg]} on {src.topic}: {why}"
                )
            return
        self.refusing[src.topic].clear()  # a good one: the next bad one is said again
        if fields is None:
            return  # a lost fix: nothing, as the GPS Leaf publishes nothing
        for name, value in fields.items():
            buf = src.buffers[name]
            if isinstance(buf, tuple):  # an array port: one message on its port's topic
                port = self.element[buf[0]]
                msg_out = self.Array(data=[float(v) for v in value])
                from std_msgs.msg import MultiArrayDimension

                label = port.rpartition(".")[2]
                msg_out.layout.dim = [
                    MultiArrayDimension(label=label, size=len(value), stride=len(value))
                ]
                self.data_pubs[port].publish(msg_out)
            else:
                self.data_pubs[buf].publish(self.Float64(data=float(value)))

    def _look_at_graph(self) -> None:
        """A driver publishing another type on a sensor topic never matches: say so, once,
        naming its node. The graph may list a publisher before it has discovered the
        publisher's node (its name is then rmw's placeholder): it is said at a later look,
        once named, or without a name after :data:`UNNAMED_LOOKS` looks."""
        for src in self.robot.inbound:
            want = ROS2_TYPE[src.role.msg]
            for info in self.node.get_publishers_info_by_topic(src.topic):
                key = (src.topic, info.topic_type)
                if info.topic_type == want or key in self.wrong_types:
                    continue
                who = info.node_name
                if not who or who == UNKNOWN_NODE:
                    self.unnamed[key] = looks = self.unnamed.get(key, 0) + 1
                    if looks < UNNAMED_LOOKS:
                        continue
                    who = "a node the ROS graph does not name"
                self.wrong_types.add(key)
                self.node.get_logger().warning(
                    f"{who} publishes {info.topic_type} on {src.topic}, "
                    f"expected {want}: its messages are not read"
                )

    # -- out --------------------------------------------------------------------------------
    def _on_power(self, src: Source, buffer: str, msg: Any) -> None:
        """A wheel power: once both are new, the command goes out, stamped with ``/clock``."""
        value = float(msg.data)
        if not math.isfinite(value):
            self.node.get_logger().warning(
                f"dropped {value!r} on {names.topic(buffer)}: not sent to {src.topic}"
            )
            return
        fresh = self.fresh[src.topic]
        self.values[buffer] = value
        fresh.add(buffer)
        if fresh < set(buffers_of(src)):
            return
        fresh.clear()
        with self.lock:
            stamp = self.stamp
        period = 1 / float(self.world.leaves[src.leaf].freq)
        ctx = Context(stamp, stamp[0] + stamp[1] / 1e9, period, DEFAULT_ORIGIN)
        out = build(src, self.values, self.params[src.leaf], ctx)
        self.cmd_pubs[src.topic].publish(fill(self.classes[src.role.msg](), out))

    def run_clock(self, speed: float, stop: threading.Event) -> None:
        """``/clock`` = wall seconds since start times ``speed``, until ``stop``."""
        wall0 = time.monotonic()
        while not stop.is_set():
            ns = int((time.monotonic() - wall0) * speed * 1e9)
            msg = self.Clock()
            msg.clock.sec, msg.clock.nanosec = ns // 10**9, ns % 10**9
            with self.lock:
                self.stamp = (ns // 10**9, ns % 10**9)
            try:
                self.clock_pub.publish(msg)
            except Exception:  # the context went down (Ctrl-C) before stop was set: done
                return
            stop.wait(CLOCK_PERIOD)  # the clock's own tick: pacing is this node's job


def read_local(manifest: Path) -> list[str]:
    """The Leaves that run in the simulator (``config/amsa.yaml``'s ``local``)."""
    data = load_yaml(manifest).data
    local = data.get("local") if isinstance(data, dict) else None
    if not isinstance(local, list) or not all(isinstance(p, str) for p in local):
        raise ConfigError("expected local: the Leaves of the simulator", file=manifest)
    return local


def main(scenario_file: str, manifest_file: str) -> None:
    """Run the boundary node of the package's scenario until shut down (parameters
    ``speed``, ``check_frames``; a bad one is one line, exit 2)."""
    rclpy = env.rclpy(NODE)
    from rcl_interfaces.msg import ParameterDescriptor
    from rclpy.executors import ExternalShutdownException

    try:
        scenario = load_scenario(Path(scenario_file))
        robot = robot_of(scenario, read_local(Path(manifest_file)))
    except AmsaError as exc:
        print(f"error: {NODE}: {exc}", file=sys.stderr)
        sys.exit(2)
    rclpy.init(args=sys.argv)
    node = rclpy.create_node(NODE)
    anything = ParameterDescriptor(dynamic_typing=True)  # a launch argument's 2 or 2.0
    speed_raw = node.declare_parameter("speed", 1.0, anything).value
    check_raw = node.declare_parameter("check_frames", True, anything).value
    try:
        speed = float(speed_raw)
    except (TypeError, ValueError):
        speed = math.nan
    if not speed > 0 or math.isinf(speed) or not isinstance(check_raw, bool):
        print(
            f"error: {NODE}: speed must be a positive number and check_frames true or false, "
            f"got speed={speed_raw!r} check_frames={check_raw!r}",
            file=sys.stderr,
        )
        node.destroy_node()
        rclpy.try_shutdown()
        sys.exit(2)
    boundary = Boundary(node, scenario, robot, check_raw)
    stop = threading.Event()
    clock = threading.Thread(target=boundary.run_clock, args=(speed, stop), daemon=True)
    clock.start()
    try:
        spin_until_shutdown(node)  # not rclpy.spin: spin.py says why
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        stop.set()
        clock.join()
        refused = {t: n for t, n in boundary.refused.items() if n}
        if refused:
            said = ", ".join(f"{n} on {t}" for t, n in refused.items())
            # the context is down (Ctrl-C): stderr, not /rosout
            print(f"{NODE}: driver messages dropped: {said}", file=sys.stderr)
        node.destroy_node()
        rclpy.try_shutdown()
